// vtkGraupelSimulation's checkpoint and restart files (CheckpointFile,
// RestartFile): a JSON manifest beside one XML piece per rank holding the
// output and the core's state bytes. "Checkpoint files" in Filters/README.md
// gives the format and the rules a restart checks.
//
// Written so that a kill at any moment leaves a restart that is whole: each
// checkpoint's pieces have names of their own (the output index in them),
// each is written under a temporary name, flushed to the disk and renamed;
// the manifest, which names them, is written the same way and last; only
// then are the pieces of earlier checkpoints removed. A reader therefore
// finds either the previous manifest with its pieces or the new one with
// its own, never a piece torn or of another output.
#include "vtkGraupelSimulation.h"

#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkXMLDataObjectWriter.h"
#include "vtkXMLGenericDataObjectReader.h"
#include "vtkXMLWriter.h"
#include "vtk_jsoncpp.h"

#include "GraupelPieces.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace {
// Flushes a written file to the disk (so that a rename after it never
// names a file whose bytes are still only in memory when the machine
// stops); false if it cannot be opened or synced.
bool Sync(const std::string &path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) {
    return false;
  }
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

// Puts a finished temporary file in place of path: synced, then renamed.
bool Publish(const std::string &part, const std::string &path) {
  if (Sync(part) && std::rename(part.c_str(), path.c_str()) == 0) {
    return true;
  }
  std::remove(part.c_str());
  return false;
}

// The piece of rank r for output index i: <stem>.<i>.<r>.<extension>.
std::string PieceName(const std::string &stem, int index, int r, const std::string &extension) {
  return stem + "." + std::to_string(index) + "." + std::to_string(r) + "." + extension;
}

// Writes path: the output with the state's bytes in the field array
// graupel_state, under a temporary name, then put in place. "" or why not.
std::string WritePiece(vtkXMLWriter *writer, vtkDataObject *output,
                       const std::vector<unsigned char> &bytes, const std::string &path) {
  vtkSmartPointer<vtkDataObject> copy = vtk::TakeSmartPointer(output->NewInstance());
  copy->ShallowCopy(output);
  vtkNew<vtkFieldData> fd;
  fd->ShallowCopy(output->GetFieldData());
  vtkNew<vtkUnsignedCharArray> state;
  state->SetName("graupel_state");
  state->SetNumberOfTuples(static_cast<vtkIdType>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), state->GetPointer(0));
  fd->AddArray(state);
  copy->SetFieldData(fd);
  writer->SetInputData(copy);
  const std::string part = path + ".part";
  writer->SetFileName(part.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  if (!writer->Write() || writer->GetErrorCode() != 0) {
    std::remove(part.c_str());
    return "its piece " + path + " could not be written";
  }
  if (!Publish(part, path)) {
    return "its piece " + path + " could not be put in place (" + std::strerror(errno) + ")";
  }
  return std::string();
}

// Writes the manifest's text whole, flushed, then renamed, after every
// piece it names: a reader never sees half a manifest, nor one whose
// pieces are missing. "" or why not.
std::string WriteManifest(const Json::Value &root, const std::string &manifest) {
  // Every double to the last bit (17 digits), as the restart compares them.
  Json::StreamWriterBuilder builder;
  builder["indentation"] = "  ";
  builder["precision"] = 17;
  const std::string part = manifest + ".part";
  std::ofstream out(part, std::ios::binary | std::ios::trunc);
  out << Json::writeString(builder, root) << "\n";
  out.close();
  if (!out) {
    std::remove(part.c_str());
    return "the manifest could not be written";
  }
  return Publish(part, manifest) ? std::string() : "the manifest could not be put in place";
}

// The state bytes of a manifest's piece (beside the manifest, holding as
// many bytes as the manifest says): "" with bytes filled, or why not.
std::string ReadPieceState(const Json::Value &piece, const std::string &folder,
                           std::vector<unsigned char> &bytes) {
  const std::string file = folder + piece["file"].asString();
  std::ostringstream m;
  if (piece["file"].asString().find('/') != std::string::npos || !std::ifstream(file).good()) {
    m << "names the piece " << file << ", which could not be opened; keep the pieces "
      << "beside the manifest";
    return m.str();
  }
  vtkNew<vtkXMLGenericDataObjectReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkDataObject *data = reader->GetOutputDataObject(0);
  vtkUnsignedCharArray *state = data ? vtkUnsignedCharArray::SafeDownCast(
                                           data->GetFieldData()->GetAbstractArray("graupel_state"))
                                     : nullptr;
  if (!state || state->GetNumberOfComponents() != 1) {
    m << "names the piece " << file
      << ", which holds no state (field array graupel_state); write it again";
  } else if (!piece["bytes"].isIntegral() ||
             piece["bytes"].asInt64() != static_cast<Json::Int64>(state->GetNumberOfTuples())) {
    m << "names the piece " << file << ", whose state holds " << state->GetNumberOfTuples()
      << " bytes where the manifest says " << piece["bytes"].asString()
      << "; it belongs to another checkpoint";
  } else {
    bytes.assign(state->GetPointer(0), state->GetPointer(0) + state->GetNumberOfTuples());
  }
  return m.str();
}

// Removes this rank's pieces of other checkpoints (<stem>.<i>.<rank>.<ext>
// with i not index) and temporary files a killed writer left, in folder.
void RemoveStalePieces(const std::string &folder, const std::string &stem, int index, int rank,
                       const std::string &extension) {
  DIR *dir = ::opendir(folder.empty() ? "." : folder.c_str());
  if (!dir) {
    return;
  }
  const std::string head = stem + ".", tail = "." + std::to_string(rank) + "." + extension;
  const std::string keep = PieceName(stem, index, rank, extension);
  std::vector<std::string> stale;
  while (const dirent *e = ::readdir(dir)) {
    const std::string name = e->d_name;
    std::string body = name;
    const bool part = body.size() > 5 && body.compare(body.size() - 5, 5, ".part") == 0;
    if (part) {
      body.erase(body.size() - 5);
    }
    if (body == keep && !part) {
      continue;
    }
    if (body.size() <= head.size() + tail.size() || body.compare(0, head.size(), head) != 0 ||
        body.compare(body.size() - tail.size(), tail.size(), tail) != 0) {
      continue;
    }
    const std::string middle = body.substr(head.size(), body.size() - head.size() - tail.size());
    if (!middle.empty() && middle.find_first_not_of("0123456789") == std::string::npos) {
      stale.push_back(name);
    }
  }
  ::closedir(dir);
  for (const std::string &name : stale) {
    std::remove((folder + name).c_str());
  }
}
// The manifest's folder (with its slash) and its name without ".json".
void SplitManifestPath(const std::string &path, std::string &folder, std::string &stem) {
  const size_t slash = path.find_last_of('/');
  folder = slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
  stem = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = stem.rfind(".json");
  if (dot != std::string::npos && dot + 5 == stem.size()) {
    stem.erase(dot);
  }
}

// The whole grid's points of a grid simulation's terrain (0 x 0 otherwise).
void GridPoints(vtkImageData *terrain, int points[2]) {
  points[0] = points[1] = 0;
  if (terrain) {
    int dims[3];
    terrain->GetDimensions(dims);
    points[0] = dims[0];
    points[1] = dims[1];
  }
}
} // namespace

int vtkGraupelSimulation::WriteCheckpointFile(vtkDataObject *output) {
  const std::string manifest = this->CheckpointFile;
  if (this->WrittenIndex == this->StateIndex && this->WrittenFile == manifest) {
    return 1; // this state is there already (a second port's request)
  }
  graupel::Pieces &pieces = *this->PieceLayout;
  const bool split = pieces.IsSplit();
  const int rank = pieces.GetRank();
  const int ranks = split ? pieces.GetNumberOfRanks() : 1;
  const std::string label = this->GetSimulationLabel();
  std::string folder, stem;
  SplitManifestPath(manifest, folder, stem);
  // The XML writer of the output's type (.vti for an image).
  vtkSmartPointer<vtkXMLWriter> writer =
      vtk::TakeSmartPointer(vtkXMLDataObjectWriter::NewWriter(output->GetDataObjectType()));
  const std::string extension = writer ? writer->GetDefaultFileExtension() : "vtk";
  const int index = this->StateIndex;
  const std::string file = PieceName(stem, index, split ? rank : 0, extension);

  // This rank's piece: its output with the core's state, byte for byte.
  // Unsplit, every rank holds the whole state: rank 0 writes it.
  std::string why;
  std::vector<unsigned char> bytes;
  const bool writes = split || rank == 0;
  if (writes) {
    if (!writer) {
      why = "its output, a " + std::string(output->GetClassName()) + ", has no XML format";
    } else if (!this->SaveState(bytes)) {
      why = label + " keeps no checkpoints of its state";
    } else {
      why = WritePiece(writer, output, bytes, folder + file);
    }
  }
  // Every rank's rows and bytes to rank 0 (sums of what each rank alone
  // fills in), and whether any rank failed.
  std::vector<double> table(3 * static_cast<size_t>(ranks) + 1, 0.0);
  const size_t me = split ? static_cast<size_t>(rank) : 0;
  table[3 * me] = split ? pieces.GetOwnFirstRow() : 0;
  table[3 * me + 1] = split ? pieces.GetOwnFirstRow() + pieces.GetOwnRows() - 1 : -1;
  table[3 * me + 2] = static_cast<double>(bytes.size());
  table.back() = why.empty() ? 0.0 : 1.0;
  if (split) {
    graupel::Pieces::Allreduce(&pieces, table.data(), static_cast<int>(table.size()),
                               GR_REDUCE_SUM);
  }
  if (why.empty() && table.back() != 0.0) {
    why = "another rank could not write its piece";
  }
  if (why.empty() && rank == 0) {
    int points[2];
    GridPoints(vtkImageData::GetData(this->GetInputInformation(0, 0)), points);
    if (!split) {
      table[1] = points[1] - 1;
    }
    Json::Value root(Json::objectValue);
    root["format"] = "graupel-checkpoint";
    root["version"] = 1;
    root["simulation"] = label;
    root["class"] = this->GetClassName();
    root["output_index"] = this->StateIndex;
    root["time"] = this->StateTime;
    root["output_interval"] = this->OutputInterval;
    if (vtkDataArray *steps = output->GetFieldData()->GetArray("steps")) {
      root["steps"] = steps->GetTuple1(0);
    }
    root["grid"].append(points[0]);
    root["grid"].append(points[1]);
    root["split"] = split;
    root["ranks"] = ranks;
    Json::Value &list = root["pieces"] = Json::Value(Json::arrayValue);
    for (int r = 0; r < ranks; ++r) {
      const size_t q = 3 * static_cast<size_t>(r);
      Json::Value piece(Json::objectValue);
      piece["rank"] = r;
      piece["rows"].append(static_cast<Json::Int64>(table[q]));
      piece["rows"].append(static_cast<Json::Int64>(table[q + 1]));
      piece["file"] = PieceName(stem, index, r, extension);
      piece["bytes"] = static_cast<Json::Int64>(table[q + 2]);
      list.append(piece);
    }
    why = WriteManifest(root, manifest);
  }
  const bool failed = pieces.AnyRank(!why.empty());
  if (failed) {
    vtkErrorMacro(<< label << " could not write its CheckpointFile " << manifest << ": "
                  << (why.empty() ? std::string("another rank could not write its part") : why)
                  << "; check that the folder exists and can be written to.");
    return 0;
  }
  // The new manifest is in place on every rank's word: earlier pieces go.
  if (writes) {
    RemoveStalePieces(folder, stem, index, split ? rank : 0, extension);
  }
  this->CheckpointFileCount += writes ? 1 : 0;
  this->WrittenIndex = this->StateIndex;
  this->WrittenFile = manifest;
  return 1;
}

int vtkGraupelSimulation::ReadRestartFile() {
  graupel::Pieces &pieces = *this->PieceLayout;
  const bool split = pieces.IsSplit();
  const int rank = pieces.GetRank();
  const int ranks = split ? pieces.GetNumberOfRanks() : 1;
  const std::string label = this->GetSimulationLabel();
  const std::string manifest = this->RestartFile;
  std::string folder, stem;
  SplitManifestPath(manifest, folder, stem);
  std::string why;
  std::vector<unsigned char> bytes;
  int index = -1;

  Json::Value root;
  {
    std::ifstream in(manifest, std::ios::binary);
    Json::CharReaderBuilder builder;
    std::string errors;
    if (!in) {
      why = "could not be opened; give the .json a CheckpointFile wrote";
    } else if (!Json::parseFromStream(builder, in, &root, &errors) || !root.isObject() ||
               root.get("format", "").asString() != "graupel-checkpoint") {
      why = "is not a Graupel checkpoint manifest; give the .json a CheckpointFile wrote";
    }
  }
  auto integer = [&root](const char *key) {
    const Json::Value &v = root[key];
    return v.isInt() ? v.asInt() : -1;
  };
  if (why.empty()) {
    const std::string simulation = root.get("simulation", "").asString();
    const Json::Value &grid = root["grid"];
    const Json::Value &list = root["pieces"];
    int points[2];
    GridPoints(vtkImageData::GetData(this->GetInputInformation(0, 0)), points);
    const int wroteRanks = integer("ranks");
    const bool wroteSplit = root.get("split", false).asBool();
    index = integer("output_index");
    const double time = root.get("time", -1.0).asDouble();
    const double interval = root.get("output_interval", 0.0).asDouble();
    std::ostringstream m;
    if (simulation != label) {
      m << "was written by " << (simulation.empty() ? "another program" : simulation) << ", not "
        << label << "; give a checkpoint of this simulation";
    } else if (!grid.isArray() || grid.size() != 2 || !grid[0].isInt() || !grid[1].isInt() ||
               grid[0].asInt() != points[0] || grid[1].asInt() != points[1]) {
      m << "holds a grid of " << (grid.isArray() && grid.size() == 2 ? grid[0].asString() : "?")
        << " x " << (grid.isArray() && grid.size() == 2 ? grid[1].asString() : "?")
        << " points, but the Input has " << points[0] << " x " << points[1]
        << "; restart with the terrain it was written with";
    } else if (wroteRanks != ranks || wroteSplit != split) {
      auto says = [](int n, bool s) {
        return s ? "split over " + std::to_string(n) + " ranks" : std::string("whole on one rank");
      };
      m << "was written " << says(wroteRanks, wroteSplit) << " and this run is "
        << says(ranks, split) << "; restart it on "
        << (wroteSplit ? std::to_string(wroteRanks) + " ranks (mpiexec -n " +
                             std::to_string(wroteRanks) + ")"
                       : std::string("one process"));
    } else if (index < 0 || index >= this->GetNumberOfOutputTimes() ||
               this->GetOutputTime(index) != time || interval != this->OutputInterval) {
      m << "was written at t = " << time << " s (output " << index << ", OutputInterval "
        << interval << " s), which is not an output time of this run (OutputInterval "
        << this->OutputInterval << " s, EndTime " << this->EndTime
        << " s); restart with the output times it was written with";
    } else if (!list.isArray() || static_cast<int>(list.size()) != ranks ||
               !list[rank].isObject() || !list[rank]["rows"].isArray() ||
               list[rank]["rows"].size() != 2 || !list[rank]["file"].isString()) {
      m << "lists no piece for rank " << rank << "; give the .json a CheckpointFile wrote";
    } else {
      const Json::Value &piece = list[rank];
      const int lo = piece["rows"][0].asInt(), hi = piece["rows"][1].asInt();
      const int ownLo = split ? pieces.GetOwnFirstRow() : 0;
      const int ownHi = split ? ownLo + pieces.GetOwnRows() - 1 : points[1] - 1;
      if (lo != ownLo || hi != ownHi) {
        m << "gives rank " << rank << " the rows " << lo << " to " << hi
          << ", and this run gives it " << ownLo << " to " << ownHi
          << "; restart with the terrain and ranks it was written with";
      } else {
        m << ReadPieceState(piece, folder, bytes);
      }
    }
    why = m.str();
  }
  if (why.empty() && !this->LoadState(bytes)) {
    why = "holds a state that does not fit this simulation; restart with the inputs and "
          "properties it was written with";
  }
  const bool failed = pieces.AnyRank(!why.empty());
  if (failed) {
    vtkErrorMacro(<< label << "'s RestartFile " << manifest << " "
                  << (why.empty() ? std::string("could not be read by another rank") : why) << ".");
    return 0;
  }
  this->StateIndex = this->RestartIndex = index;
  this->StateTime = this->GetOutputTime(index);
  this->StateLost = false;
  // Kept as a checkpoint too: going back before it and forward again loads it.
  this->Checkpoints.push_back(Checkpoint{index, std::move(bytes)});
  return 1;
}
