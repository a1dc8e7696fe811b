// vtkRainRunoffFilter's outputs: the ledger recorded at each output time
// (the hydrograph's rows), the image with the water, the flood maps and the
// hydrograph table.
#include "vtkRainRunoffFilter.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkTable.h"

#include "graupel/rain_runoff.h"

#include "GraupelArrays.h"
#include "GraupelPieces.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

using graupel::AddValue;

int vtkRainRunoffFilter::RecordLedger(int index) {
  gr_rain_runoff_ledger ledger;
  const gr_status st = gr_rain_runoff_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Rain Runoff could not read its ledger",
                               gr_rain_runoff_last_error(this->Simulation));
  }
  if (this->Ledgers.size() <= static_cast<size_t>(index)) {
    this->Ledgers.resize(static_cast<size_t>(index) + 1);
  }
  this->Ledgers[static_cast<size_t>(index)] = {this->GetOutputTime(index), ledger.rain_volume,
                                               ledger.infiltrated_volume,  ledger.outflow_volume,
                                               ledger.stored_volume,       ledger.balance_error,
                                               ledger.inflow_volume};
  const int gauges = static_cast<int>(this->GaugeCells.size() / 2);
  if (this->GaugeRows.size() <= static_cast<size_t>(index)) {
    this->GaugeRows.resize(static_cast<size_t>(index) + 1);
  }
  std::vector<float> &row = this->GaugeRows[static_cast<size_t>(index)];
  row.assign(3 * static_cast<size_t>(gauges), 0.0f);
  graupel::Pieces &pieces = this->GetPieces();
  if (!pieces.IsSplit()) {
    const gr_status sst =
        gr_rain_runoff_sample(this->Simulation, this->GaugeCells.data(), gauges, row.data());
    if (sst != GR_OK) {
      return this->ReportFailure(sst, "Rain Runoff could not read its gauges",
                                 gr_rain_runoff_last_error(this->Simulation));
    }
    return 1;
  }
  // A split run: each rank samples the gauges on its own rows (the core's
  // own cells from row 0); the others add -0.0, which leaves every float,
  // -0.0 and NaN included, as it is, so every rank's table holds the owner's bits.
  std::vector<int> mine;
  std::vector<int> which;
  for (int g = 0; g < gauges; ++g) {
    const int j = this->GaugeCells[2 * static_cast<size_t>(g) + 1] - pieces.GetOwnFirstRow();
    if (j >= 0 && j < pieces.GetOwnRows()) {
      mine.push_back(this->GaugeCells[2 * static_cast<size_t>(g)]);
      mine.push_back(j);
      which.push_back(g);
    }
  }
  std::vector<float> sampled(3 * which.size());
  gr_status sst = gr_rain_runoff_sample(this->Simulation, mine.data(),
                                        static_cast<int>(which.size()), sampled.data());
  std::vector<double> sum(3 * static_cast<size_t>(gauges), -0.0);
  for (size_t k = 0; k < which.size(); ++k) {
    for (size_t w = 0; w < 3; ++w) {
      sum[3 * static_cast<size_t>(which[k]) + w] = sampled[3 * k + w];
    }
  }
  // Collective whatever this rank's read gave: no rank waits alone.
  const bool failed = pieces.AnyRank(sst != GR_OK);
  if (sst == GR_OK && !failed && gauges > 0) {
    sst = graupel::Pieces::Allreduce(&pieces, sum.data(), static_cast<int>(sum.size()),
                                     GR_REDUCE_SUM);
  }
  if (sst != GR_OK) {
    return this->ReportFailure(sst, "Rain Runoff could not read its gauges",
                               gr_rain_runoff_last_error(this->Simulation));
  }
  if (failed) {
    vtkErrorMacro("Rain Runoff could not read its gauges: another rank failed to read its own.");
    return 0;
  }
  for (size_t k = 0; k < row.size(); ++k) {
    row[k] = static_cast<float>(sum[k]);
  }
  return 1;
}

int vtkRainRunoffFilter::FillOutput(vtkDataObject *outputObject, vtkInformation *outInfo) {
  const int fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_WATER_SURFACE, GR_FIELD_VELOCITY,
                        GR_FIELD_DISCHARGE,   GR_FIELD_INFILTRATED,   GR_FIELD_ELEVATION};
  if (!this->FillImage(
          outputObject, outInfo, fields, static_cast<int>(sizeof(fields) / sizeof(fields[0])),
          [this](int f, float *values) {
            return static_cast<int>(
                gr_rain_runoff_get_field(this->Simulation, static_cast<gr_field>(f), values));
          },
          [this]() { return gr_rain_runoff_last_error(this->Simulation); })) {
    return 0;
  }
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);

  gr_rain_runoff_ledger ledger;
  const gr_status st = gr_rain_runoff_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Rain Runoff could not read its ledger",
                               gr_rain_runoff_last_error(this->Simulation));
  }
  vtkFieldData *fd = output->GetFieldData();
  AddValue(fd, "time", ledger.time);
  AddValue(fd, "steps", static_cast<double>(ledger.steps));
  AddValue(fd, "initial_volume", ledger.initial_volume);
  AddValue(fd, "rain_volume", ledger.rain_volume);
  AddValue(fd, "infiltrated_volume", ledger.infiltrated_volume);
  AddValue(fd, "outflow_volume", ledger.outflow_volume);
  AddValue(fd, "inflow_volume", ledger.inflow_volume);
  AddValue(fd, "stored_volume", ledger.stored_volume);
  AddValue(fd, "balance_error", ledger.balance_error);
  AddValue(fd, "max_depth", ledger.max_depth);
  if (!this->AddMaps(output)) {
    return 0;
  }
  if (this->OutputVector) {
    vtkDataObject *table =
        this->OutputVector->GetInformationObject(1)->Get(vtkDataObject::DATA_OBJECT());
    if (!this->FillHydrograph(table)) {
      return 0;
    }
    this->OutputsFilled = true;
  }
  return 1;
}

int vtkRainRunoffFilter::AddMaps(vtkDataObject *outputObject) {
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);
  vtkImageData *input = vtkImageData::GetData(this->GetInputInformation(0, 0));
  if (!output || !input) {
    return 0;
  }
  int in[6], out[6], dims[3];
  input->GetExtent(in);
  output->GetExtent(out);
  input->GetDimensions(dims);
  graupel::Pieces &pieces = this->GetPieces();
  // The core's own rows (a split run's strip, or the whole grid), then the
  // output's rows, some of them a neighbouring rank's (as FillImage does).
  const int ownRows = pieces.IsSplit() ? pieces.GetOwnRows() : dims[1];
  std::vector<float> own(static_cast<size_t>(dims[0]) * static_cast<size_t>(ownRows));
  std::vector<float> rows;
  const vtkIdType w = out[1] - out[0] + 1, h = out[3] - out[2] + 1;
  for (int m = 0; m < GR_RAIN_RUNOFF_MAP_COUNT; ++m) {
    const gr_rain_runoff_map map = static_cast<gr_rain_runoff_map>(m);
    const gr_status st = gr_rain_runoff_get_map(this->Simulation, map, own.data());
    if (st != GR_OK) {
      return this->ReportFailure(st, "Rain Runoff could not read its flood maps",
                                 gr_rain_runoff_last_error(this->Simulation));
    }
    std::string why;
    if (!pieces.Rows(own.data(), dims[0], 1, out[2] - in[2], out[3] - in[2], rows, why)) {
      vtkErrorMacro("Rain Runoff could not assemble its flood maps from the neighbouring ranks: "
                    << why << ".");
      return 0;
    }
    vtkNew<vtkFloatArray> a;
    a->SetName(gr_rain_runoff_map_name(map));
    a->SetNumberOfTuples(w > 0 && h > 0 ? w * h : 0);
    // The output is the requested piece of the whole grid (FillImage's crop).
    for (vtkIdType j = 0; j < h; ++j) {
      for (vtkIdType i = 0; i < w; ++i) {
        const size_t src = static_cast<size_t>(j) * static_cast<size_t>(dims[0]) +
                           static_cast<size_t>(out[0] - in[0] + i);
        a->SetValue(j * w + i, rows[src]);
      }
    }
    output->GetPointData()->AddArray(a);
  }
  return 1;
}

int vtkRainRunoffFilter::FillHydrograph(vtkDataObject *tableObject) {
  vtkTable *table = vtkTable::SafeDownCast(tableObject);
  if (!table) {
    return 1; // a pipeline that asked for the image only
  }
  // One table for the whole run, on rank 0: every rank holds the same rows
  // (the ledger is reduced over the ranks), and ParaView appends the ranks'
  // tables when it delivers them (a client's chart and CSV would hold every
  // row once per rank). The other ranks give the columns without rows.
  const bool holder = this->GetPieces().GetRank() == 0;
  const int rows = holder ? this->GetStateIndex() + 1 : 0;
  if (holder && (rows < 1 || this->Ledgers.size() < static_cast<size_t>(rows) ||
                 this->GaugeRows.size() < static_cast<size_t>(rows))) {
    vtkErrorMacro("Rain Runoff's hydrograph lacks the ledger of an output time before "
                  << this->GetStateTime() << " s; this is a bug: please report it.");
    return 0;
  }
  // rain_volume_rate, not rain_rate: the volume a second on the domain (m^3/s),
  // not the RainRate property (mm/h) nor the rain_rate input array (m/s).
  const char *names[] = {"time",         "rain_volume_rate", "inflow_rate",    "infiltration_rate",
                         "outflow_rate", "stored_volume",    "outflow_volume", "balance_error"};
  const int columns = static_cast<int>(sizeof(names) / sizeof(names[0]));
  std::vector<vtkSmartPointer<vtkDoubleArray>> c(static_cast<size_t>(columns));
  for (int k = 0; k < columns; ++k) {
    c[static_cast<size_t>(k)] = vtkSmartPointer<vtkDoubleArray>::New();
    c[static_cast<size_t>(k)]->SetName(names[k]);
    c[static_cast<size_t>(k)]->SetNumberOfTuples(rows);
  }
  for (int r = 0; r < rows; ++r) {
    const std::array<double, 7> &now = this->Ledgers[static_cast<size_t>(r)];
    const std::array<double, 7> &before = this->Ledgers[static_cast<size_t>(r > 0 ? r - 1 : 0)];
    const double span = now[0] - before[0];
    // The mean rate over the interval that ends at this row; no interval
    // ends at row 0, whose rates are NaN (a line chart starts at row 1
    // instead of ramping up from a 0 that never was).
    const double none = std::numeric_limits<double>::quiet_NaN();
    auto rate = [&](int i) { return span > 0.0 ? (now[i] - before[i]) / span : none; };
    const double values[] = {now[0], rate(1), rate(6), rate(2), rate(3), now[4], now[3], now[5]};
    for (int k = 0; k < columns; ++k) {
      c[static_cast<size_t>(k)]->SetValue(r, values[k]);
    }
  }
  for (int k = 0; k < columns; ++k) {
    table->AddColumn(c[static_cast<size_t>(k)]);
  }
  // Three columns per gauge.
  const int gauges = static_cast<int>(this->GaugeCells.size() / 2);
  const char *what[] = {"depth", "surface", "discharge"};
  for (int gk = 0; gk < gauges; ++gk) {
    for (int w = 0; w < 3; ++w) {
      vtkNew<vtkFloatArray> a;
      a->SetName(("gauge" + std::to_string(gk) + "_" + what[w]).c_str());
      a->SetNumberOfTuples(rows);
      for (int r = 0; r < rows; ++r) {
        const std::vector<float> &g = this->GaugeRows[static_cast<size_t>(r)];
        a->SetValue(r, g[3 * static_cast<size_t>(gk) + static_cast<size_t>(w)]);
      }
      table->AddColumn(a);
    }
  }
  return 1;
}
