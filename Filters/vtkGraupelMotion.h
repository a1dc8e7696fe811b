/**
 * @class   vtkGraupelMotion
 * @brief   The pose of a rigid object as a function of time, from
 *          properties instead of a temporal input.
 *
 * Three kinds of motion, combined into one pose (object frame to world,
 * evaluated with GLM in double precision):
 *
 *   M(t) = T(p(t)) * O(t) * T(c) * R(w t, a) * T(-c)
 *
 * - translation p(t) = Velocity * t (m/s), or, when a path is set, the point
 *   at arc length PathSpeed * t along the path polyline (held at its end);
 * - O(t) is the identity, or along a path the rotation about z (then a
 *   pitch) that turns the object's +x axis onto the path's tangent;
 * - R is the rotation by AngularVelocity * t (deg/s; right-handed) about
 *   the axis RotationAxis through RotationCenter (object frame): with the
 *   centre at a wheel's hub, Velocity v and AngularVelocity v / r (in deg/s)
 *   the wheel rolls without slipping.
 *
 * Time t is absolute, seconds from the simulation's start. The result is a
 * 4x4 column-major matrix, the layout of gr_mesh.transform (graupel.h).
 */
#ifndef vtkGraupelMotion_h
#define vtkGraupelMotion_h

#include "GraupelFiltersModule.h"
#include "vtkObject.h"

#include <string>
#include <vector>

class vtkPolyData;

class GRAUPELFILTERS_EXPORT vtkGraupelMotion : public vtkObject {
public:
  static vtkGraupelMotion *New();
  vtkTypeMacro(vtkGraupelMotion, vtkObject);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Translation speed, m/s (default 0 0 0); ignored while a path is set. */
  vtkSetVector3Macro(Velocity, double);
  vtkGetVector3Macro(Velocity, double);
  ///@}

  ///@{
  /** Rotation speed about RotationAxis, degrees per second (default 0). */
  vtkSetMacro(AngularVelocity, double);
  vtkGetMacro(AngularVelocity, double);
  ///@}

  ///@{
  /** Axis of the rotation, object frame (default 0 1 0: a wheel rolling along x). */
  vtkSetVector3Macro(RotationAxis, double);
  vtkGetVector3Macro(RotationAxis, double);
  ///@}

  ///@{
  /** A point on the rotation axis, object frame, metres (default 0 0 0). */
  vtkSetVector3Macro(RotationCenter, double);
  vtkGetVector3Macro(RotationCenter, double);
  ///@}

  ///@{
  /** The path: a polyline in the world, metres; fewer than 2 points: none. */
  void AddPathPoint(double x, double y, double z);
  void ClearPath();
  int GetNumberOfPathPoints() const { return static_cast<int>(this->Path.size() / 3); }
  /** Length of the path, metres. */
  double GetPathLength() const;
  ///@}

  ///@{
  /** Speed along the path, m/s (default 1). */
  vtkSetMacro(PathSpeed, double);
  vtkGetMacro(PathSpeed, double);
  ///@}

  /** The pose at time t (s): 16 doubles, column-major. */
  void EvaluatePose(double t, double matrix[16]);

  /** A point of the object frame moved to the world at time t. */
  void TransformPoint(double t, const double in[3], double out[3]);

  ///@{
  /**
   * What the filters that pose objects by properties share (Snow
   * Accumulation, Snow Deformation). Each check returns an empty string, or
   * one sentence that starts with `filter` (e.g. "Snow Deformation").
   */
  /** ObjectVelocity (m/s), ObjectAngularVelocity (deg/s) and RotationAxis are finite. */
  static std::string CheckObjectMotion(const char *filter, const double velocity[3],
                                       double angularVelocity, const double axis[3]);
  /**
   * Reads a Path input into xyz (3 per point; cleared, and left empty
   * without a path): its first polyline, or without lines its points in
   * order. Refuses a non-finite point and fewer than two distinct points.
   */
  static std::string ReadPath(const char *filter, vtkPolyData *path, std::vector<double> &xyz);
  /** Along a path object k moves at |velocity|, which must be above 0. */
  static std::string CheckPathSpeed(const char *filter, size_t object, const double velocity[3]);
  /**
   * The pose (column-major) at time t (s) of an object whose frame is
   * centred on `centre` (world, m): without a path the centre moves at
   * `velocity`; along `path` (xyz, 2 points or more) it follows the path at
   * |velocity| with +x along the tangent; both turn at angularVelocity
   * (deg/s) about `axis` through the centre.
   */
  static void PoseObject(const double centre[3], const double velocity[3], double angularVelocity,
                         const double axis[3], const std::vector<double> &path, double t,
                         double matrix[16]);
  ///@}

protected:
  vtkGraupelMotion() = default;
  ~vtkGraupelMotion() override = default;

  double Velocity[3] = {0.0, 0.0, 0.0};
  double AngularVelocity = 0.0;
  double RotationAxis[3] = {0.0, 1.0, 0.0};
  double RotationCenter[3] = {0.0, 0.0, 0.0};
  double PathSpeed = 1.0;
  std::vector<double> Path;

private:
  vtkGraupelMotion(const vtkGraupelMotion &) = delete;
  void operator=(const vtkGraupelMotion &) = delete;
};

#endif
