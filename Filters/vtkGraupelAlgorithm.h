/**
 * @class   vtkGraupelAlgorithm
 * @brief   Base of every Graupel filter that runs an OpenCL core.
 *
 * Holds what every such filter shares: the `Device` property (gpu, cpu, auto
 * or part of a device name; GRAUPEL_DEVICE applies when it is empty or
 * "auto"), the process-wide OpenCL context shared by all filters, the
 * translation of core status codes into one vtkErrorMacro sentence, and the
 * `graupel_device` field-data string that says where an output was computed.
 */
#ifndef vtkGraupelAlgorithm_h
#define vtkGraupelAlgorithm_h

#include "GraupelFiltersModule.h"
#include "vtkImageAlgorithm.h"

struct gr_context;
class vtkDataObject;

class GRAUPELFILTERS_EXPORT vtkGraupelAlgorithm : public vtkImageAlgorithm {
public:
  vtkTypeMacro(vtkGraupelAlgorithm, vtkImageAlgorithm);
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
   * The largest buffer the chosen device allows, in bytes (0 when there is
   * no such device): a grid of float fields must stay below it. Picks the
   * device if no update has yet.
   */
  vtkTypeInt64 GetDeviceMaxBufferBytes();

protected:
  vtkGraupelAlgorithm();
  ~vtkGraupelAlgorithm() override;

  /**
   * The shared context for the chosen device, acquired on first use.
   * nullptr after reporting the reason with vtkErrorMacro.
   */
  gr_context *GetContext();

  /**
   * Reports a failed core call as one error sentence ("<what>: <detail>")
   * and returns 0, the value RequestData returns on failure.
   */
  int ReportFailure(int status, const char *what);

  /** Adds the `graupel_device` string to the output's field data. */
  void AddDeviceFieldData(vtkDataObject *output);

  char *Device = nullptr;

private:
  vtkGraupelAlgorithm(const vtkGraupelAlgorithm &) = delete;
  void operator=(const vtkGraupelAlgorithm &) = delete;

  gr_context *Context = nullptr;
};

#endif
