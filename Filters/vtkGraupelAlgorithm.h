/**
 * @class   vtkGraupelAlgorithm
 * @brief   Base of every Graupel filter that runs an OpenCL core.
 *
 * Holds what every such filter shares: the `Device` property (gpu, cpu, auto
 * or part of a device name; GRAUPEL_DEVICE applies when it is empty or
 * "auto"; in an MPI run local rank N takes the N-th device the request
 * matches, wrapping around, unless the request names one with ":N"), the process-wide OpenCL
 * context shared by all filters, the translation of core status codes into one vtkErrorMacro
 * sentence, and the `graupel_device` field-data string that says where an output was computed.
 *
 * It derives from vtkAlgorithm, not vtkImageAlgorithm, so that a simulation
 * whose output is points (vtkPolyData) shares it; it keeps the behaviour of
 * vtkImageAlgorithm that Graupel's image sources rely on: one input and one
 * output port, both vtkImageData unless a subclass fills the port
 * information otherwise, and the requests dispatched to RequestInformation,
 * RequestUpdateExtent and RequestData.
 *
 * Errors are reported once. A RequestData that fails has already said why
 * in one vtkErrorMacro sentence; ProcessRequest then empties the outputs,
 * stamps them with the requested time and returns 1 instead of 0. Returning
 * 0 made vtkExecutive::CallAlgorithm add "Algorithm ... returned failure for
 * request: vtkInformation ..." with a dump of the request after the
 * sentence, and an output without DATA_TIME_STEP made
 * vtkStreamingDemandDrivenPipeline::NeedToExecuteData run the filter again
 * for each of ParaView's later requests at the same time (the pipeline
 * update, the representation, the data information), each repeating the
 * sentence: three errors and two dumps for one mistake. An empty output is
 * what downstream filters and ParaView's representations expect of a failed
 * filter anyway. The same holds for a failed RequestInformation: the output
 * advertises an empty extent and the data pass is skipped without a second
 * message.
 */
#ifndef vtkGraupelAlgorithm_h
#define vtkGraupelAlgorithm_h

#include "GraupelFiltersModule.h"
#include "vtkAlgorithm.h"
#include "vtkSmartPointer.h" // for the views put in the inputs
#include "vtkVersionMacros.h"

// VTK's aborted-output protocol (AbortOutput, vtkAlgorithm::ABORTED) came
// after 9.2.x: ParaView 5.11's VTK has it, Debian's VTK 9.1 does not.
#if VTK_VERSION_NUMBER >= VTK_VERSION_CHECK(9, 2, 20220614)
#define GRAUPEL_VTK_ABORT_OUTPUT 1
#else
#define GRAUPEL_VTK_ABORT_OUTPUT 0
#endif

#include <map>
#include <string>
#include <utility>
#include <vector>

struct gr_context;
class vtkDataArray;
class vtkDataObject;
class vtkImageData;
class vtkMultiProcessController;

class GRAUPELFILTERS_EXPORT vtkGraupelAlgorithm : public vtkAlgorithm {
public:
  vtkTypeMacro(vtkGraupelAlgorithm, vtkAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /**
   * OpenCL device: "auto" (default: GRAUPEL_DEVICE, else the first GPU, else
   * the first CPU), "gpu", "cpu", or part of a device name as `clinfo -l`
   * lists it. Changing it moves the next update to that device.
   */
  virtual void SetDevice(const char *device);
  vtkGetStringMacro(Device);
  ///@}

  /** Name of the device the last update ran on ("" before the first). */
  const char *GetDeviceName() const;

  /**
   * From a ParaView client: asks the remote server behind `toServer` (the
   * session's DATA_SERVER_ROOT controller) to abort the Graupel update it
   * runs now, which stops at its next progress report (see
   * GraupelRemoteAbort.h). pvpython: graupel.remote.abort_update(). False
   * when `toServer` is no socket connection.
   */
  static bool SendRemoteAbort(vtkMultiProcessController *toServer);

#ifndef __VTK_WRAP__
  /**
   * On a server process: how to find the server root's controller for its
   * client, whose socket Graupel's updates poll for a remote abort. The
   * plugin installs it (vtkGraupelRemote.h); nullptr turns the poll off.
   */
  static void SetRemoteClientLookup(vtkMultiProcessController *(*lookup)());
  /** On a server process: a client request's progress bracket begins, ends (GraupelRemoteAbort.h).
   */
  static void BeginRemoteRequest();
  static void EndRemoteRequest();
#endif

  /**
   * The largest buffer the chosen device allows, in bytes (0 when there is
   * no such device): a grid of float fields must stay below it. Picks the
   * device if no update has yet.
   */
  vtkTypeInt64 GetDeviceMaxBufferBytes();

  ///@{
  /** The output on port 0 (or port), of the type the port declares. */
  vtkDataObject *GetOutput();
  vtkDataObject *GetOutput(int port);
  ///@}

  /** Dispatches the pipeline requests; see the class comment for failures. */
  vtkTypeBool ProcessRequest(vtkInformation *request, vtkInformationVector **inInfo,
                             vtkInformationVector *outInfo) override;

protected:
  vtkGraupelAlgorithm();
  ~vtkGraupelAlgorithm() override;

  virtual int RequestInformation(vtkInformation *, vtkInformationVector **,
                                 vtkInformationVector *) {
    return 1;
  }
  virtual int RequestUpdateExtent(vtkInformation *, vtkInformationVector **,
                                  vtkInformationVector *) {
    return 1;
  }
  virtual int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) {
    return 1;
  }

  /** vtkImageData on every port unless a subclass says otherwise. */
  int FillInputPortInformation(int port, vtkInformation *info) override;
  int FillOutputPortInformation(int port, vtkInformation *info) override;

  /**
   * The shared context for the chosen device, acquired on first use.
   * nullptr after reporting the reason with vtkErrorMacro.
   */
  gr_context *GetContext();

  /**
   * Reports a failed core call as one error sentence ("<what>: <detail>")
   * and returns 0, the value RequestData returns on failure. detail is the
   * failing handle's own message when given (gr_<core>_last_error), else
   * the thread's latest core error.
   */
  int ReportFailure(int status, const char *what, const char *detail = nullptr);

  /**
   * For the checks that return their sentence (empty when all is well):
   * reports a non-empty one as this filter's error and returns 0, else 1.
   */
  int ReportError(const std::string &sentence);

public:
  /**
   * Called by the setters that clamp (GraupelParameterTable.h): value was
   * asked for property, used is what the setter keeps. A value moved into
   * the range is remembered, and the next update warns once, in one
   * sentence, what was asked and what is used ("Rain Runoff: RainRate must
   * be from 0 to 3600 mm/h; it was set to -5 mm/h, so 0 mm/h is used.").
   * Setting the same used value again (the GUI writing back what is used)
   * keeps the note; any other value in range drops it. While a note is
   * kept, output 0's field data holds graupel_used_<property> (the value
   * used), which the GUI reads to show that value in the panel.
   */
  void NoteSetting(const char *property, double value, double used, double current,
                   const char *unit, double min, double max);

protected:
  /** Adds the `graupel_device` string to the output's field data. */
  void AddDeviceFieldData(vtkDataObject *output);

  /** Empties every output and stamps it with its requested time. */
  void EmptyOutputs(vtkInformationVector *outInfo);

  /**
   * The abort of a source or filter that computes in bands (Procedural
   * Terrain, Cloud Cover, Terrain Analysis), by vtkGraupelSimulation's
   * protocol: call it as RequestData starts (started false: an update that
   * begins with AbortExecute set, as pqGraupelAbortStarter sets it again
   * while the aborted Render lasts, returns its empty output at once and
   * silently) and after each band (started true: warns "<label>: the update
   * was aborted; the output is empty."). When an abort was asked for, it is
   * consumed, the output is marked aborted (AbortOutput: the executive
   * empties it and the next request computes again; on VTK 9.1, Modified())
   * and true is returned: RequestData then returns 1.
   */
  bool AbortRequested(const char *label, bool started);

  char *Device = nullptr;

  /**
   * The input port that takes a terrain, whose heights come from the Height
   * Array (input array 0; see GraupelTerrain.h): 0 by default, -1 for none.
   * While RequestData runs, that port (and, when the heights are cells,
   * every other image input of the raster's size) holds the view of cell
   * centres with `elevation` that the filters read: they look up
   * `elevation` as point data and nothing else.
   */
  virtual int GetTerrainPort() {
    return this->GetNumberOfInputPorts() > 0 ? 0 : -1;
  }

  /**
   * The heights of the terrain the filter reads (its Input during
   * RequestData, the view or the input itself): a one-component point
   * array; nullptr with the reason in *why when there is none.
   */
  vtkDataArray *TerrainHeights(vtkImageData *terrain, std::string *why = nullptr);

  /** The terrain's heights are cell data: the outputs are the cells' centres. */
  bool GetTerrainCells() const {
    return this->TerrainCells;
  }

private:
  vtkGraupelAlgorithm(const vtkGraupelAlgorithm &) = delete;
  void operator=(const vtkGraupelAlgorithm &) = delete;

  gr_context *Context = nullptr;
  // RequestInformation failed (and said why): the data pass is skipped.
  bool InformationFailed = false;
  // The terrain's heights are cells (RequestInformation) and the views.
  bool TerrainCells = false;
  struct TerrainViews;
  TerrainViews *Views = nullptr;
  // Puts the terrain views in the inputs' information; false after saying
  // why. restore gets what to put back after RequestData.
  bool
  SwapInViews(vtkInformationVector **inInfo,
              std::vector<std::pair<vtkInformation *, vtkSmartPointer<vtkDataObject>>> &restore);
  // Values moved into their range: property -> the sentence, whether it
  // was said, and the value used.
  struct ClampNote {
    std::string sentence;
    bool said;
    double used;
  };
  std::map<std::string, ClampNote> Clamped;
  // "Rain Runoff" from vtkRainRunoffFilter: the name users see.
  std::string Label() const;
};

#endif
