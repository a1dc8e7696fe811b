"""Graupel on a remote ParaView server (pvserver): stopping an update.

ParaView 5.11 cannot stop a server's update from the client. Graupel's
simulations and band-wise filters listen for an abort message of their own
on the server (see Filters/GraupelRemoteAbort.h), which this module sends:

    from paraview.simple import *
    from graupel import remote
    Connect("server.example.org", 11111)
    ...
    handler = servermanager.ActiveConnection.Session.GetProgressHandler()
    def on_progress(handler, event):
        if handler.GetLastProgress() >= 50:     # percent, from the server
            remote.abort_update()
    handler.AddObserver("ProgressEvent", on_progress)
    rain.UpdatePipeline(36000.0)   # returns at the next progress report

The update ends with an empty output and a warning that names the
simulated time it reached; the next update runs again (from the state
reached or the last checkpoint). The server sends progress once a second,
so a progress observer is where a script decides.
"""


def abort_update(connection=None):
    """Asks the server of `connection` (default: the active one) to abort
    the Graupel update it runs now. Returns False for a builtin session
    (no server: set AbortExecute on the filter's VTK object instead) or when
    the message could not be sent."""
    from paraview import servermanager
    from paraview.modules.vtkRemotingCore import vtkPVSession
    from .GraupelFilters import vtkGraupelAlgorithm

    connection = connection or servermanager.ActiveConnection
    if connection is None or not connection.IsRemote():
        return False
    controller = connection.Session.GetController(vtkPVSession.DATA_SERVER_ROOT)
    return bool(controller is not None and vtkGraupelAlgorithm.SendRemoteAbort(controller))
