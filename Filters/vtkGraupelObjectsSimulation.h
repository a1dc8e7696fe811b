/**
 * @class   vtkGraupelObjectsSimulation
 * @brief   Base of the simulations with rigid objects (Snow Accumulation,
 *          Snow Deformation): the Objects and Path inputs, the motion
 *          properties and the objects' outputs.
 *
 * Input 0 is the terrain (vtkImageData); input 1 (`Objects`, optional) is
 * vtkPolyData or a multiblock of them, one object per non-empty leaf, read
 * whole (a composite pipeline would otherwise run the filter once per
 * block); input 2 (`Path`, optional) is a polyline. Objects that do not
 * advertise time steps move by the properties (vtkGraupelMotion): the centre
 * at ObjectVelocity (m/s, a leaf's field data `velocity` replaces it for
 * that object), or along the Path at that velocity's length; the object
 * turns at ObjectAngularVelocity (deg/s) about RotationAxis through its
 * centre.
 * Objects that advertise time steps are read at each: their geometry is the
 * pose.
 *
 * Output 1 is the objects, a vtkPolyData or a multiblock following the
 * Objects input's type (vtkGraupelSimulation gives it the simulation's times).
 */
#ifndef vtkGraupelObjectsSimulation_h
#define vtkGraupelObjectsSimulation_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelSimulation.h"

#include <vector>

class vtkAlgorithmOutput;
class vtkDataObject;
class vtkPolyData;
namespace graupel {
struct Object; // one object as a core sees it (GraupelObjects.h)
}

class GRAUPELFILTERS_EXPORT vtkGraupelObjectsSimulation : public vtkGraupelSimulation {
public:
  vtkTypeMacro(vtkGraupelObjectsSimulation, vtkGraupelSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /**
   * Velocity of the centres of the objects that have no time steps, m/s
   * (default 0 0 0); along a Path its length is the speed.
   */
  vtkSetVector3Macro(ObjectVelocity, double);
  vtkGetVector3Macro(ObjectVelocity, double);
  ///@}

  ///@{
  /** Rotation speed of the objects about RotationAxis through their centres, deg/s (default 0). */
  vtkSetMacro(ObjectAngularVelocity, double);
  vtkGetMacro(ObjectAngularVelocity, double);
  ///@}

  ///@{
  /** Axis of that rotation, object frame (default 0 1 0: a wheel rolling along x). */
  vtkSetVector3Macro(RotationAxis, double);
  vtkGetVector3Macro(RotationAxis, double);
  ///@}

  /** Connects the objects (input port 1). */
  void SetObjectsConnection(vtkAlgorithmOutput *output);
  /** Connects the optional path (input port 2). */
  void SetPathConnection(vtkAlgorithmOutput *output);

  /** Output 1 takes the Objects input's type; the rest goes to the base. */
  vtkTypeBool ProcessRequest(vtkInformation *request, vtkInformationVector **inInfo,
                             vtkInformationVector *outInfo) override;

protected:
  /**
   * The objects as the core takes them: at most maxObjects, with points at
   * the same place merged into one vertex (closed meshes) or one vertex per
   * point (snow handed back per point), each mesh passing gr_mesh_validate
   * with `closed`.
   */
  vtkGraupelObjectsSimulation(size_t maxObjects, bool mergePoints, int closed);
  ~vtkGraupelObjectsSimulation() override;

  int FillInputPortInformation(int port, vtkInformation *info) override;

  /** ObjectVelocity, ObjectAngularVelocity and RotationAxis are finite; 0 after one sentence. */
  int CheckObjectMotion();
  /** Reads the path (input 2) and the objects (input 1) at set-up; 0 after one sentence. */
  int ReadObjectInputs(vtkInformationVector **inputVector);
  /** Reads the objects into Objects; 0 after one sentence. */
  int ReadObjects(vtkDataObject *objects);
  /** The pose (column-major) of object k at time t. */
  void Pose(size_t k, double t, double matrix[16]) const;
  /**
   * For FillOutput: the objects' outputs (1 and up) at the state's time,
   * each through FillObjectOutput, on piece 0 only so that an MPI run shows
   * each object once; 0 after one sentence.
   */
  int FillObjectOutputs();
  /** Fills output `port` (1 and up, emptied) at time t; 0 after one sentence. */
  virtual int FillObjectOutput(int port, vtkDataObject *output, double t) = 0;
  /** The motion properties, as the subclasses' PrintSelf ends. */
  void PrintObjectMotion(ostream &os, vtkIndent indent);

  double ObjectVelocity[3] = {0.0, 0.0, 0.0};
  double ObjectAngularVelocity = 0.0;
  double RotationAxis[3] = {0.0, 1.0, 0.0};

  std::vector<graupel::Object> Objects;
  std::vector<double> Path; // xyz per point; empty when none
  bool ObjectsTemporal = false;
  double ObjectsReadAt = 0.0;

private:
  vtkGraupelObjectsSimulation(const vtkGraupelObjectsSimulation &) = delete;
  void operator=(const vtkGraupelObjectsSimulation &) = delete;

  const size_t MaxObjects;
  const bool MergePoints;
  const int ClosedObjects;
};

#endif
