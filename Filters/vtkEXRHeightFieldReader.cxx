#include "vtkEXRHeightFieldReader.h"

#include "GraupelRanges.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include "graupel/exr_io.h"

#include "GraupelMemory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <sys/stat.h>
#include <vector>

vtkStandardNewMacro(vtkEXRHeightFieldReader);

// The image most recently read, kept until the file or its time stamp
// changes, so RequestInformation and RequestData read the file once.
struct vtkEXRHeightFieldReader::Cache {
  std::string path;
  long long mtime = 0;
  long long size = 0;
  gr_exr_image image{};
  Cache() = default;
  Cache(const Cache &) = delete;
  Cache &operator=(const Cache &) = delete;
  ~Cache() { gr_exr_image_free(&this->image); }
};

vtkEXRHeightFieldReader::vtkEXRHeightFieldReader() {
  this->SetNumberOfInputPorts(0);
}

vtkEXRHeightFieldReader::~vtkEXRHeightFieldReader() {
  this->SetFileName(nullptr);
}

int vtkEXRHeightFieldReader::CanReadFile(const char *filename) {
  if (!filename) {
    return 0;
  }
  FILE *f = std::fopen(filename, "rb");
  if (!f) {
    return 0;
  }
  unsigned char magic[4] = {0, 0, 0, 0};
  size_t n = std::fread(magic, 1, 4, f);
  std::fclose(f);
  return n == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
}

bool vtkEXRHeightFieldReader::Load() {
  if (!this->FileName || !*this->FileName) {
    vtkErrorMacro("EXR Height Field Reader: no FileName was set; give the path of an .exr file.");
    return false;
  }
  struct stat st;
  if (stat(this->FileName, &st) != 0) {
    vtkErrorMacro("EXR Height Field Reader: the file '"
                  << this->FileName << "' does not exist or cannot be accessed.");
    this->Loaded.reset();
    return false;
  }
  long long mtime = static_cast<long long>(st.st_mtime);
  if (this->Loaded && this->Loaded->path == this->FileName && this->Loaded->mtime == mtime &&
      this->Loaded->size == static_cast<long long>(st.st_size)) {
    return true;
  }
  std::unique_ptr<Cache> cache(new Cache);
  char err[1024] = "";
  gr_status status = gr_exr_read(this->FileName, &cache->image, err, sizeof(err));
  if (status != GR_OK) {
    vtkErrorMacro("EXR Height Field Reader: " << err);
    this->Loaded.reset();
    return false;
  }
  cache->path = this->FileName;
  cache->mtime = mtime;
  cache->size = static_cast<long long>(st.st_size);
  this->Loaded = std::move(cache);
  return true;
}

void vtkEXRHeightFieldReader::Geometry(double spacing[3], double origin[3]) const {
  const gr_exr_meta &meta = this->Loaded->image.meta;
  const bool fileSpacing = this->GeometryFromFile && meta.has_spacing;
  const bool fileOrigin = this->GeometryFromFile && meta.has_origin;
  spacing[0] = fileSpacing ? meta.spacing[0] : this->Spacing[0];
  spacing[1] = fileSpacing ? meta.spacing[1] : this->Spacing[1];
  spacing[2] = 1.0;
  for (int d = 0; d < 3; ++d) {
    origin[d] = fileOrigin ? meta.origin[d] : this->Origin[d];
  }
}

int vtkEXRHeightFieldReader::RequestInformation(vtkInformation *, vtkInformationVector **,
                                                vtkInformationVector *outputVector) {
  // A failure here skips RequestData: empty the output so that an earlier
  // result does not stay in place of the failed one.
  vtkImageData *previous = vtkImageData::GetData(outputVector);
  if (!this->Load()) {
    if (previous) {
      previous->Initialize();
    }
    return 0;
  }
  double spacing[3], origin[3];
  this->Geometry(spacing, origin);
  if (!(spacing[0] > 0.0) || !(spacing[1] > 0.0)) {
    vtkErrorMacro("EXR Height Field Reader: Spacing must be above 0 m in x and y; got "
                  << spacing[0] << " " << spacing[1] << ".");
    if (previous) {
      previous->Initialize();
    }
    return 0;
  }
  const gr_exr_image &img = this->Loaded->image;
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  int extent[6] = {0, img.width - 1, 0, img.height - 1, 0, 0};
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  return 1;
}

namespace {
// "velocity.x" -> base "velocity", component 0; anything else -> -1.
int VectorComponent(const std::string &name, std::string &base) {
  static const char *suffixes[3] = {".x", ".y", ".z"};
  for (int c = 0; c < 3; ++c) {
    size_t n = name.size();
    if (n > 2 && name.compare(n - 2, 2, suffixes[c]) == 0) {
      base = name.substr(0, n - 2);
      return c;
    }
  }
  return -1;
}
} // namespace

int vtkEXRHeightFieldReader::RequestData(vtkInformation *, vtkInformationVector **,
                                         vtkInformationVector *outputVector) {
  vtkImageData *output = vtkImageData::GetData(outputVector);
  output->Initialize();
  if (!this->Load()) {
    return 0;
  }
  const gr_exr_image &img = this->Loaded->image;
  const vtkIdType n = static_cast<vtkIdType>(img.width) * img.height;
  // The reader checked its own planes before decoding; the output's arrays
  // copy them, a float a channel a point, from what is left.
  gr_memory_need need = {};
  need.points = static_cast<double>(n);
  need.host = need.points * img.nchannels * sizeof(float);
  const std::string refusal =
      graupel::MemoryRefusal(nullptr, "EXR Height Field Reader",
                             graupel::GridSubject(img.width, img.height, "image") + " of " +
                                 std::to_string(img.nchannels) + " channels",
                             need, "read a smaller file or free memory");
  if (!refusal.empty()) {
    vtkErrorMacro(<< refusal);
    return 0;
  }

  std::vector<vtkSmartPointer<vtkFloatArray>> arrays;
  std::vector<bool> used(img.nchannels, false);
  // Vectors first: NAME.x, NAME.y and NAME.z together make one array.
  for (int c = 0; c < img.nchannels; ++c) {
    std::string base;
    if (VectorComponent(img.names[c], base) != 0) {
      continue;
    }
    int comp[3] = {c, gr_exr_find_channel(&img, (base + ".y").c_str()),
                   gr_exr_find_channel(&img, (base + ".z").c_str())};
    if (comp[1] < 0 || comp[2] < 0) {
      continue;
    }
    vtkNew<vtkFloatArray> a;
    a->SetName(base.c_str());
    a->SetNumberOfComponents(3);
    a->SetNumberOfTuples(n);
    float *dst = a->GetPointer(0);
    for (vtkIdType k = 0; k < n; ++k) {
      for (int d = 0; d < 3; ++d) {
        dst[3 * k + d] = img.data[comp[d]][k];
      }
    }
    for (int d = 0; d < 3; ++d) {
      used[comp[d]] = true;
    }
    arrays.emplace_back(a.Get());
  }
  for (int c = 0; c < img.nchannels; ++c) {
    if (used[c]) {
      continue;
    }
    vtkNew<vtkFloatArray> a;
    // A lone channel is a height map (its name is often "Y" or "R"), unless
    // it already carries one of Graupel's field names, which is kept.
    bool keep = img.nchannels > 1 || gr_field_from_name(img.names[c]) >= 0;
    a->SetName(keep ? img.names[c] : "elevation");
    a->SetNumberOfTuples(n);
    std::memcpy(a->GetPointer(0), img.data[c], sizeof(float) * static_cast<size_t>(n));
    arrays.emplace_back(a.Get());
  }

  double spacing[3], origin[3];
  this->Geometry(spacing, origin);
  output->SetExtent(0, img.width - 1, 0, img.height - 1, 0, 0);
  output->SetSpacing(spacing);
  output->SetOrigin(origin);
  for (int f = 0; f < img.meta.nfields; ++f) {
    const gr_exr_meta_field &m = img.meta.fields[f];
    if (m.is_string) {
      vtkNew<vtkStringArray> a;
      a->SetName(m.name);
      a->SetNumberOfValues(m.count);
      for (int k = 0; k < m.count; ++k) {
        a->SetValue(k, m.strings[k]);
      }
      output->GetFieldData()->AddArray(a);
    } else {
      vtkNew<vtkDoubleArray> a;
      a->SetName(m.name);
      a->SetNumberOfComponents(m.ncomponents);
      a->SetNumberOfTuples(m.count / m.ncomponents);
      std::copy(m.numbers, m.numbers + m.count, a->GetPointer(0));
      output->GetFieldData()->AddArray(a);
    }
  }
  vtkIdType nonFinite = 0;
  for (auto &a : arrays) {
    if (std::strcmp(a->GetName(), "elevation") == 0) {
      float *v = a->GetPointer(0);
      for (vtkIdType k = 0; k < n; ++k) {
        v[k] = static_cast<float>(v[k] * this->HeightScale);
        nonFinite += std::isfinite(v[k]) ? 0 : 1;
      }
      output->GetPointData()->SetScalars(a);
    } else {
      output->GetPointData()->AddArray(a);
    }
  }
  if (nonFinite > 0) {
    vtkWarningMacro("EXR Height Field Reader: '" << this->FileName << "' has " << nonFinite
                                                 << " elevation values that are NaN or infinite"
                                                    " (no-data cells); Rain Runoff treats NaN"
                                                    " points as outside its domain (its"
                                                    " NoDataBoundary), the other simulations"
                                                    " refuse them.");
  }
  graupel::CacheRanges(output);
  return 1;
}

void vtkEXRHeightFieldReader::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Spacing: " << this->Spacing[0] << " " << this->Spacing[1] << "\n";
  os << indent << "Origin: " << this->Origin[0] << " " << this->Origin[1] << " " << this->Origin[2]
     << "\n";
  os << indent << "HeightScale: " << this->HeightScale << "\n";
  os << indent << "GeometryFromFile: " << this->GeometryFromFile << "\n";
}
