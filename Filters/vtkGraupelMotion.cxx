#include "vtkGraupelMotion.h"

#include "vtkCellArray.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

vtkStandardNewMacro(vtkGraupelMotion);

void vtkGraupelMotion::AddPathPoint(double x, double y, double z) {
  this->Path.insert(this->Path.end(), {x, y, z});
  this->Modified();
}

void vtkGraupelMotion::ClearPath() {
  this->Path.clear();
  this->Modified();
}

double vtkGraupelMotion::GetPathLength() const {
  double length = 0.0;
  for (size_t k = 3; k + 2 < this->Path.size(); k += 3) {
    const glm::dvec3 a(this->Path[k - 3], this->Path[k - 2], this->Path[k - 1]);
    const glm::dvec3 b(this->Path[k], this->Path[k + 1], this->Path[k + 2]);
    length += glm::length(b - a);
  }
  return length;
}

void vtkGraupelMotion::EvaluatePose(double t, double matrix[16]) {
  glm::dmat4 pose(1.0);
  if (this->GetNumberOfPathPoints() >= 2) {
    // Walk the polyline to arc length s; past its end the object stays at
    // the last point, facing along the last segment.
    double s = std::max(0.0, this->PathSpeed * t);
    const int n = this->GetNumberOfPathPoints();
    glm::dvec3 position(this->Path[0], this->Path[1], this->Path[2]);
    glm::dvec3 tangent(1.0, 0.0, 0.0);
    for (int k = 1; k < n; ++k) {
      const glm::dvec3 a(this->Path[3 * (k - 1)], this->Path[3 * (k - 1) + 1],
                         this->Path[3 * (k - 1) + 2]);
      const glm::dvec3 b(this->Path[3 * k], this->Path[3 * k + 1], this->Path[3 * k + 2]);
      const double len = glm::length(b - a);
      if (len <= 0.0) {
        continue; // a repeated point has no direction
      }
      tangent = (b - a) / len;
      if (s <= len || k == n - 1) {
        position = a + tangent * std::min(s, len);
        break;
      }
      s -= len;
    }
    // Heading about z, then pitch, so that +x lies along the tangent and the
    // object's z stays as close to up as the path allows.
    const double heading = std::atan2(tangent.y, tangent.x);
    const double pitch = std::atan2(tangent.z, std::hypot(tangent.x, tangent.y));
    pose = glm::translate(pose, position);
    pose = glm::rotate(pose, heading, glm::dvec3(0.0, 0.0, 1.0));
    pose = glm::rotate(pose, -pitch, glm::dvec3(0.0, 1.0, 0.0));
  } else {
    pose = glm::translate(pose,
                          glm::dvec3(this->Velocity[0], this->Velocity[1], this->Velocity[2]) * t);
  }
  const glm::dvec3 axis(this->RotationAxis[0], this->RotationAxis[1], this->RotationAxis[2]);
  if (this->AngularVelocity != 0.0 && glm::length(axis) > 0.0) {
    const glm::dvec3 c(this->RotationCenter[0], this->RotationCenter[1], this->RotationCenter[2]);
    pose = glm::translate(pose, c);
    pose = glm::rotate(pose, glm::radians(this->AngularVelocity * t), glm::normalize(axis));
    pose = glm::translate(pose, -c);
  }
  // GLM stores matrices column by column, as gr_mesh.transform does.
  const double *m = glm::value_ptr(pose);
  std::copy(m, m + 16, matrix);
}

void vtkGraupelMotion::TransformPoint(double t, const double in[3], double out[3]) {
  double m[16];
  this->EvaluatePose(t, m);
  const glm::dvec4 p = glm::make_mat4(m) * glm::dvec4(in[0], in[1], in[2], 1.0);
  out[0] = p.x;
  out[1] = p.y;
  out[2] = p.z;
}

std::string vtkGraupelMotion::CheckObjectMotion(const char *filter, const double v[3],
                                                double angularVelocity, const double axis[3]) {
  if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) &&
      std::isfinite(angularVelocity) && std::isfinite(axis[0]) && std::isfinite(axis[1]) &&
      std::isfinite(axis[2])) {
    return std::string();
  }
  std::ostringstream msg;
  msg << filter << ": ObjectVelocity (" << v[0] << " " << v[1] << " " << v[2]
      << " m/s), ObjectAngularVelocity (" << angularVelocity
      << " deg/s) and RotationAxis must be finite numbers; set them so.";
  return msg.str();
}

std::string vtkGraupelMotion::ReadPath(const char *filter, vtkPolyData *path,
                                       std::vector<double> &xyz) {
  xyz.clear();
  if (!path) {
    return std::string();
  }
  // The first polyline in its order; without lines, the points in theirs.
  vtkNew<vtkIdList> ids;
  vtkCellArray *lines = path->GetLines();
  if (lines && lines->GetNumberOfCells() > 0) {
    lines->InitTraversal();
    lines->GetNextCell(ids);
  } else {
    for (vtkIdType i = 0; i < path->GetNumberOfPoints(); ++i) {
      ids->InsertNextId(i);
    }
  }
  std::ostringstream msg;
  double length = 0.0;
  for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) {
    double p[3];
    path->GetPoint(ids->GetId(k), p);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      xyz.clear();
      msg << filter << "'s Path has a point that is not finite (point " << ids->GetId(k)
          << "); fix or remove it.";
      return msg.str();
    }
    if (k > 0) {
      const double *q = &xyz[xyz.size() - 3];
      length += std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                          (p[2] - q[2]) * (p[2] - q[2]));
    }
    xyz.insert(xyz.end(), {p[0], p[1], p[2]});
  }
  if (xyz.size() < 6 || !(length > 0.0)) {
    msg << filter << "'s Path must be a polyline of at least two distinct points; it has "
        << xyz.size() / 3 << " point(s) and a length of " << length
        << " m. Give it a polyline (e.g. a Poly Line Source) or disconnect it.";
    xyz.clear();
    return msg.str();
  }
  return std::string();
}

std::string vtkGraupelMotion::CheckPathSpeed(const char *filter, size_t object, const double v[3]) {
  if (std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > 0.0) {
    return std::string();
  }
  std::ostringstream msg;
  msg << filter
      << ": along the Path the objects move at the speed of ObjectVelocity (or of a block's "
         "'velocity'), and object "
      << object << "'s is 0 m/s; set ObjectVelocity to the speed wanted.";
  return msg.str();
}

void vtkGraupelMotion::PoseObject(const double centre[3], const double v[3], double angularVelocity,
                                  const double axis[3], const std::vector<double> &path, double t,
                                  double m[16]) {
  vtkNew<vtkGraupelMotion> motion;
  motion->SetAngularVelocity(angularVelocity);
  motion->SetRotationAxis(axis[0], axis[1], axis[2]);
  if (path.size() >= 6) {
    for (size_t p = 0; p + 2 < path.size(); p += 3) {
      motion->AddPathPoint(path[p], path[p + 1], path[p + 2]);
    }
    motion->SetPathSpeed(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    motion->EvaluatePose(t, m);
    return;
  }
  motion->SetVelocity(v[0], v[1], v[2]);
  motion->EvaluatePose(t, m);
  // The motion starts from the object's own place.
  m[12] += centre[0];
  m[13] += centre[1];
  m[14] += centre[2];
}

void vtkGraupelMotion::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Velocity: " << this->Velocity[0] << " " << this->Velocity[1] << " "
     << this->Velocity[2] << " m/s\n";
  os << indent << "AngularVelocity: " << this->AngularVelocity << " deg/s\n";
  os << indent << "RotationAxis: " << this->RotationAxis[0] << " " << this->RotationAxis[1] << " "
     << this->RotationAxis[2] << "\n";
  os << indent << "RotationCenter: " << this->RotationCenter[0] << " " << this->RotationCenter[1]
     << " " << this->RotationCenter[2] << " m\n";
  os << indent << "PathPoints: " << this->GetNumberOfPathPoints() << "\n";
  os << indent << "PathSpeed: " << this->PathSpeed << " m/s\n";
}
