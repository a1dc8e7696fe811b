/**
 * @class   vtkGraupelSimulation
 * @brief   Base of every Graupel filter that steps a simulation through time.
 *
 * A simulation filter is a time source: it advertises `TIME_STEPS` (0,
 * OutputInterval, 2 OutputInterval, ..., EndTime) and `TIME_RANGE` [0,
 * EndTime]. A requested time is snapped to the last output time at or
 * before it. The simulation state stays on the device between updates:
 *
 * - a request for a later time advances the cached state interval by
 *   interval (progress is reported per interval and an abort is honoured
 *   between intervals: the output is then empty, the state reached is kept,
 *   and the next update continues from it);
 * - a request for an earlier time restarts from the initial state;
 * - a changed property or input sets the simulation up again.
 *
 * Because the state always advances by whole output intervals from time 0,
 * the field at a time never depends on the order in which times were
 * requested (Testing/Python/test_rain_runoff.py checks it bit for bit).
 *
 * Inputs are read once, at their first time; a terrain that changes in time
 * is not followed. Every rank of an MPI run simulates the whole domain and
 * outputs its piece, so pieces equal the whole.
 *
 * Subclasses implement the five hooks below; they translate, they do not
 * compute.
 */
#ifndef vtkGraupelSimulation_h
#define vtkGraupelSimulation_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h"

class vtkImageData;

class GRAUPELFILTERS_EXPORT vtkGraupelSimulation : public vtkGraupelAlgorithm {
public:
  vtkTypeMacro(vtkGraupelSimulation, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  /** The most output times a simulation advertises. */
  static constexpr int MaximumOutputSteps = 100000;

  ///@{
  /** Simulated time at the last output, seconds (default 600). */
  vtkSetMacro(EndTime, double);
  vtkGetMacro(EndTime, double);
  ///@}

  ///@{
  /** Simulated time between outputs, seconds (default 10). */
  vtkSetMacro(OutputInterval, double);
  vtkGetMacro(OutputInterval, double);
  ///@}

  /** Number of output times: intervals up to EndTime, plus time 0. */
  int GetNumberOfOutputTimes() const;
  /** Output time k (0 <= k < GetNumberOfOutputTimes()), seconds. */
  double GetOutputTime(int k) const;

  /** Output index of the state kept on the device; -1 when there is none. */
  vtkGetMacro(StateIndex, int);
  /** How many times the state was set up or restarted (for tests). */
  vtkGetMacro(RestartCount, int);

protected:
  vtkGraupelSimulation();
  ~vtkGraupelSimulation() override;

  /**
   * Validates the inputs and creates the device state at time 0. Reports
   * its own error (one sentence naming the input, array and fix) and
   * returns 0 on failure; nothing may be left half set up then.
   */
  virtual int SetUpState(vtkInformationVector **inputVector) = 0;
  /** Back to the time-0 state of the last set-up. 0 on failure. */
  virtual int ResetState() = 0;
  /** Advances the state by seconds. 0 on failure (error reported). */
  virtual int AdvanceState(double seconds) = 0;
  /**
   * Fills output (already given the input's geometry and the requested
   * extent) with the current fields and ledger. 0 on failure.
   */
  virtual int FillOutput(vtkImageData *output, const int extent[6]) = 0;
  /** Frees the device state; must accept being called without state. */
  virtual void ReleaseState() = 0;

  /** Forgets the state, so the next update sets it up again. */
  void InvalidateState();

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestUpdateExtent(vtkInformation *, vtkInformationVector **,
                          vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  double EndTime = 600.0;
  double OutputInterval = 10.0;

private:
  vtkGraupelSimulation(const vtkGraupelSimulation &) = delete;
  void operator=(const vtkGraupelSimulation &) = delete;

  /** 0 with an error sentence when EndTime/OutputInterval are unusable. */
  int CheckTimes();
  /** Whether the state was built from this filter's and inputs' present values. */
  bool StateIsCurrent();

  int StateIndex = -1;
  int RestartCount = 0;
  vtkMTimeType StateFilterMTime = 0;
  vtkMTimeType StateInputMTime[2] = {0, 0};
};

#endif
