/**
 * An abort asked by a ParaView client of a remote server (pvserver), and a
 * client that went away during an update.
 *
 * ParaView 5.11 has no way for a client to stop a server's update: while
 * the server runs RequestData it reads nothing from its client socket, and
 * the client's abort button and pvpython have nothing to send. Graupel adds
 * one message of its own:
 *
 * - the client sends RemoteAbortTag on its socket to the server's root
 *   (SendRemoteAbort; pvpython: graupel.remote.abort_update(), the GUI: the
 *   abort button, pqGraupelAbortStarter), typically from a progress event,
 *   which the client receives while it waits for the update;
 * - on the server's root, every progress report of a Graupel update asks
 *   RemoteAbortAsked(): a poll of the client socket with no wait. The
 *   messages ahead of the abort (the client's request to clean up progress,
 *   queued behind the update) are read and kept in the communicator's
 *   buffer, which ParaView's server loop empties first once the update ends;
 *   the abort itself is consumed. A socket closed by the client (killed, or
 *   disconnected) counts as an abort too, so a server whose client is gone
 *   ends its update at the next report rather than after the whole run;
 * - the abort holds for the update it stopped: ParaView's request updates
 *   every output port in turn (each in its own progress bracket) and an
 *   aborted output makes each of those run the algorithm again, so while
 *   the abort holds, the same algorithm asked for the same time returns its
 *   empty output at once, as the GUI's abort button does in a builtin
 *   session (pqGraupelAbortStarter). It holds until the client has been
 *   quiet for a second between two requests (a person's or a script's next
 *   step, where the client's own follow-up requests come within
 *   milliseconds): EndRemoteRequest and BeginRemoteRequest, which the plugin
 *   calls at the server's progress brackets. Another time or another
 *   algorithm runs at once; the same time asked again within that second
 *   is still empty;
 * - an abort that arrives after the update ended is dropped when the server
 *   reads it (an observer of the communicator's WrongTagEvent).
 *
 * The rank that sees the abort sets AbortExecute on the running algorithm;
 * the cores and vtkGraupelSimulation agree on it over all ranks of a split
 * run. Which socket to poll is found by a lookup that the plugin installs
 * on server processes (SetClientLookup: this module uses no ParaView API).
 */
#ifndef GraupelRemoteAbort_h
#define GraupelRemoteAbort_h

class vtkMultiProcessController;

namespace graupel {

/** The message's tag: unlike ParaView's own tags (RMI 1, 2; progress 188969...). */
constexpr int RemoteAbortTag = 0x47726175; // "Grau"

/** Returns the server root's controller for its client, or nullptr. */
typedef vtkMultiProcessController *(*ClientLookup)();

/** Installs the lookup (the plugin does, on server processes). */
void SetClientLookup(ClientLookup lookup);

/**
 * Sends the abort from a client to the server it is connected to
 * (`toServer`: the session's DATA_SERVER_ROOT controller). False when it is
 * no socket connection or the send failed.
 */
bool SendRemoteAbort(vtkMultiProcessController *toServer);

/**
 * On the server's root: whether the update of `who` for `time` must stop:
 * an abort holds for (who, time), or the client closed its connection, or
 * (running, not starting) the client asked for an abort since the last
 * poll, which then holds for (who, time). Never waits; false where no
 * lookup is installed or this process has no client.
 */
bool RemoteAbortAsked(const void *who, double time, bool starting);

/** The server's progress brackets of a client request (see above). */
void BeginRemoteRequest();
void EndRemoteRequest();

} // namespace graupel

#endif
