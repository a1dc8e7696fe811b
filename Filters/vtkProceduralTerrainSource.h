/**
 * @class   vtkProceduralTerrainSource
 * @brief   Procedural terrain height field (seed 001) computed by OpenCL.
 *
 * Produces a 2-D vtkImageData (Dimensions[0] x Dimensions[1] x 1) with the
 * point array `elevation` (float32, metres, 0..HeightScale). The noise is a
 * function of world position: the same Seed gives the same field on every
 * run, a piece of the extent (MPI) is exactly that part of the whole, and
 * moving Origin pans over one endless terrain.
 *
 * NoiseType 0 is the inverted ridged multifractal that seed 001 uses for
 * snow landscapes (rounded hills, river valleys); 1 is fBm (mountain ranges),
 * 2 is billow. The normalisation is in kernels/include/graupel/procedural_terrain.h.
 */
#ifndef vtkProceduralTerrainSource_h
#define vtkProceduralTerrainSource_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h"

class GRAUPELFILTERS_EXPORT vtkProceduralTerrainSource : public vtkGraupelAlgorithm {
public:
  static vtkProceduralTerrainSource *New();
  vtkTypeMacro(vtkProceduralTerrainSource, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  enum NoiseTypes { RIDGED_MULTIFRACTAL = 0, FBM = 1, BILLOW = 2 };

  ///@{
  /** Number of points in x and y (default 512 512). */
  vtkSetVector2Macro(Dimensions, int);
  vtkGetVector2Macro(Dimensions, int);
  ///@}

  ///@{
  /** Point spacing in metres (default 2). */
  vtkSetMacro(Spacing, double);
  vtkGetMacro(Spacing, double);
  ///@}

  ///@{
  /** Position of the first point, metres (default 0 0 0). */
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  ///@}

  ///@{
  /** Random seed; equal seeds give equal terrains (default 0). */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /** 0 ridged multifractal (inverted, default), 1 fBm, 2 billow. */
  vtkSetClampMacro(NoiseType, int, 0, 2);
  vtkGetMacro(NoiseType, int);
  ///@}

  ///@{
  /** Number of octaves, 1..16 (default 6). */
  vtkSetClampMacro(Octaves, int, 1, 16);
  vtkGetMacro(Octaves, int);
  ///@}

  ///@{
  /** Base frequency in cycles per kilometre (default 4). */
  vtkSetClampMacro(Frequency, double, 1e-6, 1e4);
  vtkGetMacro(Frequency, double);
  ///@}

  ///@{
  /** Frequency ratio between octaves, 1..8 (default 2). */
  vtkSetClampMacro(Lacunarity, double, 1.0, 8.0);
  vtkGetMacro(Lacunarity, double);
  ///@}

  ///@{
  /** Amplitude ratio between octaves for fBm and billow, 0..1 (default 0.5). */
  vtkSetClampMacro(Persistence, double, 0.0, 1.0);
  vtkGetMacro(Persistence, double);
  ///@}

  ///@{
  /** Ridged multifractal offset, (0, 4] (default 1). */
  vtkSetClampMacro(Offset, double, 1e-3, 4.0);
  vtkGetMacro(Offset, double);
  ///@}

  ///@{
  /** Ridged multifractal gain, 0..16 (default 2). */
  vtkSetClampMacro(Gain, double, 0.0, 16.0);
  vtkGetMacro(Gain, double);
  ///@}

  ///@{
  /** Ridged spectral exponent H, 0..4 (default 1). */
  vtkSetClampMacro(SpectralExponent, double, 0.0, 4.0);
  vtkGetMacro(SpectralExponent, double);
  ///@}

  ///@{
  /** Ridged only: invert (seed 001's snow landscapes; default on). */
  vtkSetMacro(Invert, bool);
  vtkGetMacro(Invert, bool);
  vtkBooleanMacro(Invert, bool);
  ///@}

  ///@{
  /** Elevation range in metres: elevation lies in [0, HeightScale] (default 120). */
  vtkSetClampMacro(HeightScale, double, 0.0, 1e5);
  vtkGetMacro(HeightScale, double);
  ///@}

protected:
  vtkProceduralTerrainSource();
  ~vtkProceduralTerrainSource() override = default;

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  int Dimensions[2] = {512, 512};
  double Spacing = 2.0;
  double Origin[3] = {0.0, 0.0, 0.0};
  int Seed = 0;
  int NoiseType = RIDGED_MULTIFRACTAL;
  int Octaves = 6;
  double Frequency = 4.0;
  double Lacunarity = 2.0;
  double Persistence = 0.5;
  double Offset = 1.0;
  double Gain = 2.0;
  double SpectralExponent = 1.0;
  bool Invert = true;
  double HeightScale = 120.0;

private:
  vtkProceduralTerrainSource(const vtkProceduralTerrainSource &) = delete;
  void operator=(const vtkProceduralTerrainSource &) = delete;
};

#endif
