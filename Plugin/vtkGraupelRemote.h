/**
 * Plugin initializer: on a server process (pvserver, pvdataserver), lets
 * Graupel's updates hear a remote client's abort and notice a client that
 * went away: it installs vtkGraupelAlgorithm::SetRemoteClientLookup with a
 * lookup of the active session's CLIENT controller (the server root's socket
 * to its client; in a server of several clients, the active one's). The
 * protocol is in Filters/GraupelRemoteAbort.h. Elsewhere (the client,
 * pvpython, pvbatch) it does nothing.
 */
#ifndef vtkGraupelRemote_h
#define vtkGraupelRemote_h

void graupel_plugin_remote_abort();

#endif
