#include "vtkGeoTIFFWriter.h"

#include "vtkErrorCode.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkObjectFactory.h"
#include "vtkStringArray.h"

#include "graupel/raster_io.h"

#include <string>
#include <vector>

vtkStandardNewMacro(vtkGeoTIFFWriter);

const char *vtkGeoTIFFWriter::Label() const {
  return "GeoTIFF Writer";
}

void vtkGeoTIFFWriter::WriteData() {
  vtkImageData *input = this->GetInput();
  Planes planes;
  if (!this->ChoosePlanes(input, planes)) {
    return;
  }
  double spacing[3], origin[3];
  input->GetSpacing(spacing);
  input->GetOrigin(origin);
  std::string crs;
  if (auto *a =
          vtkStringArray::SafeDownCast(input->GetFieldData()->GetAbstractArray("graupel_crs"))) {
    if (a->GetNumberOfValues() > 0) {
      crs = a->GetValue(0);
    }
  }
  char err[1024] = "";
  if (gr_raster_write(this->FileName, planes.dims[0], planes.dims[1],
                      static_cast<int>(planes.names.size()), planes.namePtrs.data(),
                      planes.dataPtrs.data(), spacing, origin, crs.c_str(), err,
                      sizeof(err)) != GR_OK) {
    vtkErrorMacro(<< this->Label() << ": " << err);
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
  }
}
