"""A source with time steps for the simulations' temporal-input tests (Rain
Runoff's inflows, the snow filters' objects): one output, the time steps
TIMES advertised, every time asked for recorded in `requested`."""
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as SDDP


class TimedSource(VTKPythonAlgorithmBase):
    """Subclasses set TIMES and fill the output in RequestData, taking the
    time asked for from requested_time."""

    TIMES = [0.0]

    def __init__(self, output_type):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1,
                                        outputType=output_type)
        self.requested = []

    def RequestInformation(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        info.Set(SDDP.TIME_STEPS(), self.TIMES, len(self.TIMES))
        info.Set(SDDP.TIME_RANGE(), [self.TIMES[0], self.TIMES[-1]], 2)
        return 1

    def requested_time(self, outInfo):
        """The time the request asks for (0 without one), recorded."""
        info = outInfo.GetInformationObject(0)
        t = info.Get(SDDP.UPDATE_TIME_STEP()) if info.Has(SDDP.UPDATE_TIME_STEP()) else 0.0
        self.requested.append(t)
        return t
