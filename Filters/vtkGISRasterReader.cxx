#include "vtkGISRasterReader.h"

#include "GraupelRanges.h"

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

#include "graupel/raster_io.h"

#include <algorithm>
#include <string>
#include <sys/stat.h>

vtkStandardNewMacro(vtkGISRasterReader);

// The raster most recently read, kept until the file, its time stamp or the
// band changes, so RequestInformation and RequestData read it once.
struct vtkGISRasterReader::Cache {
  std::string path;
  long long mtime = 0, size = 0;
  int band = 0;
  gr_raster raster{};
  Cache() = default;
  Cache(const Cache &) = delete;
  Cache &operator=(const Cache &) = delete;
  ~Cache() { gr_raster_free(&this->raster); }
};

vtkGISRasterReader::vtkGISRasterReader() {
  this->SetNumberOfInputPorts(0);
}

vtkGISRasterReader::~vtkGISRasterReader() {
  this->SetFileName(nullptr);
}

int vtkGISRasterReader::CanReadFile(const char *filename) {
  return gr_raster_can_read(filename);
}

bool vtkGISRasterReader::Load() {
  if (!this->FileName || !*this->FileName) {
    vtkErrorMacro("GIS Raster Reader: no FileName was set; give the path of a raster file.");
    this->Loaded.reset();
    return false;
  }
  struct stat st;
  if (stat(this->FileName, &st) != 0) {
    vtkErrorMacro("GIS Raster Reader: the file '" << this->FileName
                                                  << "' does not exist or cannot be accessed.");
    this->Loaded.reset();
    return false;
  }
  const long long mtime = static_cast<long long>(st.st_mtime);
  if (this->Loaded && this->Loaded->path == this->FileName && this->Loaded->mtime == mtime &&
      this->Loaded->size == static_cast<long long>(st.st_size) &&
      this->Loaded->band == this->Band) {
    return true;
  }
  std::unique_ptr<Cache> cache(new Cache);
  char err[1024] = "";
  if (gr_raster_read(this->FileName, this->Band, &cache->raster, err, sizeof(err)) != GR_OK) {
    vtkErrorMacro("GIS Raster Reader: " << err);
    this->Loaded.reset();
    return false;
  }
  if (cache->raster.notes[0]) {
    vtkWarningMacro("GIS Raster Reader: " << cache->raster.notes << ".");
  }
  cache->path = this->FileName;
  cache->mtime = mtime;
  cache->size = static_cast<long long>(st.st_size);
  cache->band = this->Band;
  this->Loaded = std::move(cache);
  return true;
}

int vtkGISRasterReader::RequestInformation(vtkInformation *, vtkInformationVector **,
                                           vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  if (!this->Load()) {
    // Said why; an empty extent lets the data pass go through quietly and
    // leave an empty output (not an earlier result, nor a second error).
    static const int empty[6] = {0, -1, 0, -1, 0, -1};
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), empty, 6);
    return 1;
  }
  const gr_raster &r = this->Loaded->raster;
  int extent[6] = {0, r.width - 1, 0, r.height - 1, 0, 0};
  double spacing[3] = {r.spacing[0], r.spacing[1], 1.0};
  double origin[3] = {r.origin[0], r.origin[1], 0.0};
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  return 1;
}

int vtkGISRasterReader::RequestData(vtkInformation *, vtkInformationVector **,
                                    vtkInformationVector *outputVector) {
  vtkImageData *output = vtkImageData::GetData(outputVector);
  output->Initialize();
  if (!this->Loaded) {
    return 1; // RequestInformation said why; the output stays empty
  }
  const gr_raster &r = this->Loaded->raster;
  output->SetDimensions(r.width, r.height, 1);
  output->SetSpacing(r.spacing[0], r.spacing[1], 1.0);
  output->SetOrigin(r.origin[0], r.origin[1], 0.0);
  vtkNew<vtkFloatArray> heights;
  heights->SetName("elevation");
  heights->SetNumberOfTuples(static_cast<vtkIdType>(r.width) * r.height);
  std::copy(r.data, r.data + static_cast<size_t>(r.width) * r.height, heights->GetPointer(0));
  output->GetPointData()->SetScalars(heights);
  auto text = [&](const char *name, const char *value) {
    if (value) {
      vtkNew<vtkStringArray> a;
      a->SetName(name);
      a->InsertNextValue(value);
      output->GetFieldData()->AddArray(a);
    }
  };
  text("graupel_crs", r.crs_wkt);
  text("graupel_source_crs", r.source_crs);
  graupel::CacheRanges(output);
  return 1;
}

void vtkGISRasterReader::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Band: " << this->Band << "\n";
}
