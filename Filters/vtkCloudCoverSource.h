/**
 * @class   vtkCloudCoverSource
 * @brief   A drifting cloud cover image (seed 001's sky) computed by OpenCL.
 *
 * A 2-D vtkImageData of Resolution x Resolution points, Size metres wide,
 * centred on (0, 0) at height Altitude, with point arrays `cloud` (float,
 * density 0..1, the active scalars) and `sky_rgb` (3 bytes, a sky-blue to
 * white picture to show with Map Scalars off). The model (fBm noise, the
 * Cover threshold at the Seed's quantile, Elias's density curve, the drift)
 * is in kernels/include/graupel/sky.h.
 *
 * Time: the image at time t is the image at 0 moved by the wind, WindSpeed
 * towards WindDirection times t; the source advertises the time range 0 ..
 * Duration (no steps: any time may be asked for) and answers a request for
 * a time with that time's image, a pure function of the parameters and t.
 *
 * Cover, Scale, Sharpness, WindSpeed, WindDirection, Resolution, Size and
 * Seed follow the sky core's parameter table (gr_sky_param_bounds): the
 * setters clamp to it, and a value at an open end (Resolution 0, Scale or
 * Size 0) is refused with a sentence at the update.
 */
#ifndef vtkCloudCoverSource_h
#define vtkCloudCoverSource_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h"

class GRAUPELFILTERS_EXPORT vtkCloudCoverSource : public vtkGraupelAlgorithm {
public:
  static vtkCloudCoverSource *New();
  vtkTypeMacro(vtkCloudCoverSource, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Fraction of the sky clouded, 0..1 (default 0.5). */
  virtual void SetCover(double value);
  vtkGetMacro(Cover, double);
  ///@}

  ///@{
  /** Metres: the wavelength of the clouds' first octave (default 2000). */
  virtual void SetScale(double value);
  vtkGetMacro(Scale, double);
  ///@}

  ///@{
  /** Elias's CloudSharpness: lower gives denser, harder clouds (default 0.96). */
  virtual void SetSharpness(double value);
  vtkGetMacro(Sharpness, double);
  ///@}

  ///@{
  /** m/s: the clouds' drift speed (default 10). */
  virtual void SetWindSpeed(double value);
  vtkGetMacro(WindSpeed, double);
  ///@}

  ///@{
  /** Degrees clockwise from north: where the clouds move to (default 90, east). */
  virtual void SetWindDirection(double value);
  vtkGetMacro(WindDirection, double);
  ///@}

  ///@{
  /** Pixels per side (default 512). */
  virtual void SetResolution(int value);
  vtkGetMacro(Resolution, int);
  ///@}

  ///@{
  /** Metres: the image's width (default 20000). */
  virtual void SetSize(double value);
  vtkGetMacro(Size, double);
  ///@}

  ///@{
  /** Random seed; equal seeds give identical skies (default 0). */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /** Metres: the height of the image's plane (default 3000). */
  vtkSetMacro(Altitude, double);
  vtkGetMacro(Altitude, double);
  ///@}

  ///@{
  /** Seconds: the end of the advertised time range (default 3600). */
  vtkSetMacro(Duration, double);
  vtkGetMacro(Duration, double);
  ///@}

protected:
  vtkCloudCoverSource();
  ~vtkCloudCoverSource() override = default;

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  // The table's properties start at the core's defaults (the constructor).
  double Cover = 0.0;
  double Scale = 0.0;
  double Sharpness = 0.0;
  double WindSpeed = 0.0;
  double WindDirection = 0.0;
  int Resolution = 0;
  double Size = 0.0;
  int Seed = 0;
  double Altitude = 3000.0;
  double Duration = 3600.0;

private:
  vtkCloudCoverSource(const vtkCloudCoverSource &) = delete;
  void operator=(const vtkCloudCoverSource &) = delete;
};

#endif
