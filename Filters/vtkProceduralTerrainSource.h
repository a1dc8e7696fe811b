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
 *
 * The noise properties' ranges and defaults are the core's parameter table
 * (gr_procedural_terrain_param_bounds): each setter clamps to its row, and
 * a value the table leaves out at an open end (Frequency or Offset of 0) is
 * refused by the core with a sentence when the terrain is computed.
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
  virtual void SetNoiseType(int value);
  vtkGetMacro(NoiseType, int);
  ///@}

  ///@{
  /** Number of octaves (default 6). */
  virtual void SetOctaves(int value);
  vtkGetMacro(Octaves, int);
  ///@}

  ///@{
  /** Base frequency in cycles per kilometre (default 4). */
  virtual void SetFrequency(double value);
  vtkGetMacro(Frequency, double);
  ///@}

  ///@{
  /** Frequency ratio between octaves (default 2). */
  virtual void SetLacunarity(double value);
  vtkGetMacro(Lacunarity, double);
  ///@}

  ///@{
  /** Amplitude ratio between octaves for fBm and billow (default 0.5). */
  virtual void SetPersistence(double value);
  vtkGetMacro(Persistence, double);
  ///@}

  ///@{
  /** Ridged multifractal offset, above 0 (default 1). */
  virtual void SetOffset(double value);
  vtkGetMacro(Offset, double);
  ///@}

  ///@{
  /** Ridged multifractal gain (default 2). */
  virtual void SetGain(double value);
  vtkGetMacro(Gain, double);
  ///@}

  ///@{
  /** Ridged spectral exponent H (default 1). */
  virtual void SetSpectralExponent(double value);
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
  virtual void SetHeightScale(double value);
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
  // The noise properties start at the core's defaults (the constructor).
  int Seed = 0;
  int NoiseType = RIDGED_MULTIFRACTAL;
  int Octaves = 0;
  double Frequency = 0.0;
  double Lacunarity = 0.0;
  double Persistence = 0.0;
  double Offset = 0.0;
  double Gain = 0.0;
  double SpectralExponent = 0.0;
  bool Invert = true;
  double HeightScale = 0.0;

private:
  vtkProceduralTerrainSource(const vtkProceduralTerrainSource &) = delete;
  void operator=(const vtkProceduralTerrainSource &) = delete;
};

#endif
