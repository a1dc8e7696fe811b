#include "vtkEXRFieldWriter.h"

#include "vtkDataArray.h"
#include "vtkErrorCode.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStringArray.h"

#include "graupel/exr_io.h"

#include <algorithm>

vtkStandardNewMacro(vtkEXRFieldWriter);

vtkEXRFieldWriter::vtkEXRFieldWriter() = default;

vtkEXRFieldWriter::~vtkEXRFieldWriter() {
  this->SetFileName(nullptr);
}

void vtkEXRFieldWriter::AddArrayName(const char *name) {
  if (name && *name &&
      std::find(this->ArrayNames.begin(), this->ArrayNames.end(), name) == this->ArrayNames.end()) {
    this->ArrayNames.emplace_back(name);
    this->Modified();
  }
}

void vtkEXRFieldWriter::ClearArrayNames() {
  if (!this->ArrayNames.empty()) {
    this->ArrayNames.clear();
    this->Modified();
  }
}

int vtkEXRFieldWriter::GetNumberOfArrayNames() const {
  return static_cast<int>(this->ArrayNames.size());
}

const char *vtkEXRFieldWriter::GetArrayName(int i) const {
  return (i >= 0 && i < static_cast<int>(this->ArrayNames.size())) ? this->ArrayNames[i].c_str()
                                                                   : nullptr;
}

vtkImageData *vtkEXRFieldWriter::GetInput() {
  return vtkImageData::SafeDownCast(this->Superclass::GetInput());
}

int vtkEXRFieldWriter::FillInputPortInformation(int, vtkInformation *info) {
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

const char *vtkEXRFieldWriter::Label() const {
  return "EXR Field Writer";
}

bool vtkEXRFieldWriter::ChoosePlanes(vtkImageData *input, Planes &out) {
  std::vector<std::string> &names = out.names;
  std::vector<std::vector<float>> &planes = out.data;
  if (!this->FileName || !*this->FileName) {
    vtkErrorMacro(<< this->Label() << ": no FileName was set; give the path of the file to write.");
    this->SetErrorCode(vtkErrorCode::NoFileNameError);
    return false;
  }
  int dims[3];
  input->GetDimensions(dims);
  if (dims[2] != 1 || dims[0] < 1 || dims[1] < 1) {
    vtkErrorMacro(<< this->Label() << ": the input image is " << dims[0] << " x " << dims[1]
                  << " x " << dims[2] << "; only 2-D images (one point in z) can be written.");
    this->SetErrorCode(vtkErrorCode::UserError);
    return false;
  }
  vtkPointData *pd = input->GetPointData();
  std::vector<vtkDataArray *> chosen;
  if (this->ArrayNames.empty()) {
    for (int a = 0; a < pd->GetNumberOfArrays(); ++a) {
      if (vtkDataArray *arr = pd->GetArray(a)) {
        chosen.push_back(arr);
      }
    }
  } else {
    for (const std::string &name : this->ArrayNames) {
      vtkDataArray *arr = pd->GetArray(name.c_str());
      if (!arr) {
        vtkErrorMacro(<< this->Label() << ": the input has no numeric point array '" << name
                      << "'; choose among the arrays the input has.");
        this->SetErrorCode(vtkErrorCode::UserError);
        return false;
      }
      chosen.push_back(arr);
    }
  }
  if (chosen.empty()) {
    vtkErrorMacro(<< this->Label() << ": the input has no numeric point arrays to write.");
    this->SetErrorCode(vtkErrorCode::UserError);
    return false;
  }

  const vtkIdType n = static_cast<vtkIdType>(dims[0]) * dims[1];
  for (vtkDataArray *arr : chosen) {
    const int nc = arr->GetNumberOfComponents();
    const std::string base = arr->GetName() ? arr->GetName() : "unnamed";
    for (int c = 0; c < nc; ++c) {
      std::string name = base;
      if (nc == 3) {
        name += std::string(".") + "xyz"[c];
      } else if (nc > 1) {
        name += "." + std::to_string(c);
      }
      std::vector<float> plane(static_cast<size_t>(n));
      for (vtkIdType k = 0; k < n; ++k) {
        plane[static_cast<size_t>(k)] = static_cast<float>(arr->GetComponent(k, c));
      }
      names.push_back(name);
      planes.push_back(std::move(plane));
    }
  }
  for (size_t c = 0; c < names.size(); ++c) {
    out.namePtrs.push_back(names[c].c_str());
    out.dataPtrs.push_back(planes[c].data());
  }
  std::copy(dims, dims + 3, out.dims);
  return true;
}

void vtkEXRFieldWriter::WriteData() {
  vtkImageData *input = this->GetInput();
  Planes planes;
  if (!this->ChoosePlanes(input, planes)) {
    return;
  }
  // Geometry and field data (the ledger, the device name) travel in the
  // header, so a reopened file is where it was and keeps its record.
  gr_exr_meta meta{};
  double spacing[3], origin[3];
  input->GetSpacing(spacing);
  input->GetOrigin(origin);
  meta.has_spacing = 1;
  meta.spacing[0] = spacing[0];
  meta.spacing[1] = spacing[1];
  meta.has_origin = 1;
  std::copy(origin, origin + 3, meta.origin);
  struct Field {
    std::string name;
    std::vector<double> numbers;
    std::vector<std::string> strings;
    std::vector<char *> stringPtrs;
    int ncomponents = 1;
    bool isString = false;
  };
  std::vector<Field> fields;
  vtkFieldData *fd = input->GetFieldData();
  for (int a = 0; fd && a < fd->GetNumberOfArrays(); ++a) {
    vtkAbstractArray *arr = fd->GetAbstractArray(a);
    const vtkIdType nv = arr ? arr->GetNumberOfValues() : 0;
    // Unnamed, empty and oversized arrays have no place in a header.
    if (!arr || !arr->GetName() || !*arr->GetName() || nv < 1 || nv > GR_EXR_MAX_META_VALUES) {
      continue;
    }
    Field f;
    f.name = arr->GetName();
    if (auto *da = vtkDataArray::SafeDownCast(arr)) {
      f.ncomponents = da->GetNumberOfComponents();
      for (vtkIdType k = 0; k < nv; ++k) {
        f.numbers.push_back(
            da->GetComponent(k / f.ncomponents, static_cast<int>(k % f.ncomponents)));
      }
    } else if (auto *sa = vtkStringArray::SafeDownCast(arr)) {
      f.isString = true;
      for (vtkIdType k = 0; k < nv; ++k) {
        f.strings.push_back(sa->GetValue(k));
      }
    } else {
      continue;
    }
    fields.push_back(std::move(f));
  }
  std::vector<gr_exr_meta_field> metaFields;
  for (Field &f : fields) {
    gr_exr_meta_field m{};
    m.name = const_cast<char *>(f.name.c_str());
    m.is_string = f.isString ? 1 : 0;
    m.ncomponents = f.ncomponents;
    if (f.isString) {
      for (std::string &v : f.strings) {
        f.stringPtrs.push_back(const_cast<char *>(v.c_str()));
      }
      m.count = static_cast<int>(f.strings.size());
      m.strings = f.stringPtrs.data();
    } else {
      m.count = static_cast<int>(f.numbers.size());
      m.numbers = f.numbers.data();
    }
    metaFields.push_back(m);
  }
  meta.nfields = static_cast<int>(metaFields.size());
  meta.fields = metaFields.empty() ? nullptr : metaFields.data();

  char err[1024] = "";
  gr_status st = gr_exr_write_meta(
      this->FileName, planes.dims[0], planes.dims[1], static_cast<int>(planes.names.size()),
      planes.namePtrs.data(), planes.dataPtrs.data(),
      this->PixelType == HALF ? GR_EXR_HALF : GR_EXR_FLOAT, &meta, err, sizeof(err));
  if (st != GR_OK) {
    vtkErrorMacro("EXR Field Writer: " << err);
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
  }
}

void vtkEXRFieldWriter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "PixelType: " << (this->PixelType == HALF ? "half" : "float") << "\n";
  os << indent << "ArrayNames:";
  for (const std::string &name : this->ArrayNames) {
    os << " " << name;
  }
  os << "\n";
}
