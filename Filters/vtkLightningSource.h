/**
 * @class   vtkLightningSource
 * @brief   Branching lightning bolts as polylines (seed 001).
 *
 * A bolt from Start (in the cloud) to End (the strike): a main strand of
 * ControlPoints points, Strands branches grown from it, displaced sideways
 * by Jitter times the bolt's length; the model is in
 * kernels/include/graupel/sky.h. The bolt is a pure function of Seed, Variant
 * and, with a FlickerRate, the time requested (the seed reshapes a visible
 * bolt a few times: shape Variant + floor(t FlickerRate)): the same values
 * give the same points bit for bit.
 *
 * With a terrain on the optional input (any vtkDataSet; an image whose
 * points lie flat with an `elevation` array is read as that surface), End
 * is a point of the terrain's surface chosen by a hash of Seed and the shape,
 * and Start lies half the terrain's larger extent above its highest point;
 * Start and End are then not used.
 *
 * Output: vtkPolyData, one polyline per strand (main strand first), point
 * data `intensity` (1 on the main strand, 0.5 fading to 0.15 along a branch)
 * and `strand` (0 main, 1.. branches). The bolt is computed on the host: it
 * is a few hundred sequential points (sky.h says why), so this source has
 * no Device.
 *
 * ControlPoints, Strands, Jitter, Seed and FlickerRate follow the sky core's parameter
 * table (gr_sky_param_bounds): the setters clamp to it, and a ControlPoints
 * below 2 (the table's open end) is refused with a sentence at the update.
 */
#ifndef vtkLightningSource_h
#define vtkLightningSource_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h"

class GRAUPELFILTERS_EXPORT vtkLightningSource : public vtkGraupelAlgorithm {
public:
  static vtkLightningSource *New();
  vtkTypeMacro(vtkLightningSource, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Points of the main strand (default 50, the seed's; at least 2). */
  virtual void SetControlPoints(int value);
  vtkGetMacro(ControlPoints, int);
  ///@}

  ///@{
  /** Branches besides the main strand (default 4). */
  virtual void SetStrands(int value);
  vtkGetMacro(Strands, int);
  ///@}

  ///@{
  /** Lateral displacement relative to the bolt's length (default 0.1). */
  virtual void SetJitter(double value);
  vtkGetMacro(Jitter, double);
  ///@}

  ///@{
  /** Random seed; equal seeds give identical bolts (default 0). */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /** The first shape of the Seed's bolt (default 0). */
  vtkSetMacro(Variant, int);
  vtkGetMacro(Variant, int);
  ///@}

  ///@{
  /**
   * Reshapes per second (default 0: one shape at every time): at time t the
   * bolt is shape Variant + floor(t FlickerRate).
   */
  virtual void SetFlickerRate(double value);
  vtkGetMacro(FlickerRate, double);
  ///@}

  ///@{
  /**
   * Seconds: with a FlickerRate, the end of the time range the source
   * advertises (default 10); without one the bolt does not depend on time
   * and no range is advertised.
   */
  vtkSetMacro(Duration, double);
  vtkGetMacro(Duration, double);
  ///@}

  ///@{
  /** Where the bolt leaves the cloud, metres (default 0 0 1000). */
  vtkSetVector3Macro(Start, double);
  vtkGetVector3Macro(Start, double);
  ///@}

  ///@{
  /** Where the bolt strikes, metres (default 0 0 0). */
  vtkSetVector3Macro(End, double);
  vtkGetVector3Macro(End, double);
  ///@}

protected:
  vtkLightningSource();
  ~vtkLightningSource() override = default;

  int FillInputPortInformation(int port, vtkInformation *info) override;
  int FillOutputPortInformation(int port, vtkInformation *info) override;
  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  // The table's properties start at the core's defaults (the constructor).
  int ControlPoints = 0;
  int Strands = 0;
  double Jitter = 0.0;
  int Seed = 0;
  int Variant = 0;
  double FlickerRate = 0.0;
  double Duration = 10.0;
  double Start[3] = {0.0, 0.0, 1000.0};
  double End[3] = {0.0, 0.0, 0.0};

private:
  vtkLightningSource(const vtkLightningSource &) = delete;
  void operator=(const vtkLightningSource &) = delete;
};

#endif
