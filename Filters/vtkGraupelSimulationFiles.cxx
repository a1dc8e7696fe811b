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

#include "GraupelPieces.h"

#include "graupel/checkpoint.h"

#include <algorithm>
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

// A manifest (graupel/checkpoint.h) that frees its pieces.
struct Manifest : gr_checkpoint {
  Manifest() : gr_checkpoint() {}
  ~Manifest() { gr_checkpoint_free(this); }
  Manifest(const Manifest &) = delete;
  Manifest &operator=(const Manifest &) = delete;
};

// Writes the manifest's text (the core's, every double to the last bit, as
// the restart compares them) whole, flushed, then renamed, after every
// piece it names: a reader never sees half a manifest, nor one whose
// pieces are missing. "" or why not; a sentence of the core's (a manifest
// it would not write) goes to sentence.
std::string WriteManifest(const gr_checkpoint &c, const std::string &manifest,
                          std::string &sentence) {
  char *text = nullptr;
  size_t len = 0;
  char msg[1024];
  if (gr_checkpoint_format(&c, &text, &len, msg, sizeof(msg)) != GR_OK) {
    sentence = msg;
    return "its manifest could not be made";
  }
  const std::string part = manifest + ".part";
  std::ofstream out(part, std::ios::binary | std::ios::trunc);
  out.write(text, static_cast<std::streamsize>(len));
  gr_checkpoint_text_free(text);
  out.close();
  if (!out) {
    std::remove(part.c_str());
    return "the manifest could not be written";
  }
  return Publish(part, manifest) ? std::string() : "the manifest could not be put in place";
}

// The manifest's text, up to one byte more than the core reads (which it
// then refuses as too large); false if the file cannot be opened or read.
bool ReadManifestText(const std::string &manifest, std::string &text) {
  std::ifstream in(manifest, std::ios::binary | std::ios::ate);
  const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : -1;
  if (size < 0 || !in.seekg(0)) {
    return false;
  }
  text.resize(static_cast<size_t>(std::min<std::streamoff>(size, GR_CHECKPOINT_MAX_TEXT + 1)));
  in.read(&text[0], static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  return !in.bad();
}

// The state bytes of a manifest's piece (beside the manifest: the core
// refused a name with a folder in it; holding as many bytes as the
// manifest says): "" with bytes filled, or why not.
std::string ReadPieceState(const gr_checkpoint_piece &piece, const std::string &folder,
                           std::vector<unsigned char> &bytes) {
  const std::string file = folder + piece.file;
  std::ostringstream m;
  if (!std::ifstream(file).good()) {
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
  } else if (piece.bytes != static_cast<long long>(state->GetNumberOfTuples())) {
    m << "names the piece " << file << ", whose state holds " << state->GetNumberOfTuples()
      << " bytes where the manifest says " << piece.bytes << "; it belongs to another checkpoint";
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
  std::string sentence; // the core's, when it would not write the manifest
  if (why.empty() && rank == 0) {
    Manifest m;
    char msg[1024];
    if (gr_checkpoint_init(&m, ranks, msg, sizeof(msg)) != GR_OK) {
      why = std::string("its manifest could not be made (") + msg + ")";
    } else {
      std::snprintf(m.simulation, sizeof(m.simulation), "%s", label.c_str());
      std::snprintf(m.class_name, sizeof(m.class_name), "%s", this->GetClassName());
      m.output_index = this->StateIndex;
      m.time = this->StateTime;
      m.output_interval = this->OutputInterval;
      if (vtkDataArray *steps = output->GetFieldData()->GetArray("steps")) {
        m.has_steps = 1;
        m.steps = steps->GetTuple1(0);
      }
      GridPoints(vtkImageData::GetData(this->GetInputInformation(0, 0)), m.grid);
      if (!split) {
        table[1] = m.grid[1] - 1;
      }
      m.split = split ? 1 : 0;
      for (int r = 0; r < ranks; ++r) {
        const size_t q = 3 * static_cast<size_t>(r);
        gr_checkpoint_piece &piece = m.pieces[r];
        piece.rows[0] = static_cast<int>(table[q]);
        piece.rows[1] = static_cast<int>(table[q + 1]);
        std::snprintf(piece.file, sizeof(piece.file), "%s",
                      PieceName(stem, index, r, extension).c_str());
        piece.bytes = static_cast<long long>(table[q + 2]);
      }
      why = WriteManifest(m, manifest, sentence);
    }
  }
  const bool failed = pieces.AnyRank(!why.empty());
  if (failed && !sentence.empty()) {
    vtkErrorMacro(<< label << " could not write its CheckpointFile " << manifest << ": "
                  << sentence);
    return 0;
  }
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
  std::string why;      // said after "<label>'s RestartFile <manifest> "
  std::string sentence; // or the core's whole sentence on the manifest
  std::vector<unsigned char> bytes;
  int index = -1;

  // The manifest's every value checked by the core (graupel/checkpoint.h);
  // what needs this run (its label, grid, ranks, rows and output times,
  // the piece's file) checked here.
  Manifest m;
  std::string text;
  char msg[1536];
  const std::string subject = label + "'s RestartFile " + manifest;
  if (!ReadManifestText(manifest, text)) {
    why = "could not be opened; give the .json a CheckpointFile wrote";
  } else if (gr_checkpoint_parse(text.data(), text.size(), subject.c_str(), &m, msg, sizeof(msg)) !=
             GR_OK) {
    sentence = msg;
  } else {
    int points[2];
    GridPoints(vtkImageData::GetData(this->GetInputInformation(0, 0)), points);
    index = m.output_index;
    std::ostringstream say;
    if (m.simulation != label) {
      say << "was written by " << (m.simulation[0] ? m.simulation : "another program") << ", not "
          << label << "; give a checkpoint of this simulation";
    } else if (m.grid[0] != points[0] || m.grid[1] != points[1]) {
      say << "holds a grid of " << m.grid[0] << " x " << m.grid[1] << " points, but the Input has "
          << points[0] << " x " << points[1] << "; restart with the terrain it was written with";
    } else if (m.ranks != ranks || (m.split != 0) != split) {
      auto says = [](int n, bool s) {
        return s ? "split over " + std::to_string(n) + " ranks" : std::string("whole on one rank");
      };
      say << "was written " << says(m.ranks, m.split != 0) << " and this run is "
          << says(ranks, split) << "; restart it on "
          << (m.split
                  ? std::to_string(m.ranks) + " ranks (mpiexec -n " + std::to_string(m.ranks) + ")"
                  : std::string("one process"));
    } else if (index >= this->GetNumberOfOutputTimes() || this->GetOutputTime(index) != m.time ||
               m.output_interval != this->OutputInterval) {
      say << "was written at t = " << m.time << " s (output " << index << ", OutputInterval "
          << m.output_interval << " s), which is not an output time of this run (OutputInterval "
          << this->OutputInterval << " s, EndTime " << this->EndTime
          << " s); restart with the output times it was written with";
    } else {
      // The core checked that there is one piece per rank, in rank order.
      const gr_checkpoint_piece &piece = m.pieces[rank];
      const int ownLo = split ? pieces.GetOwnFirstRow() : 0;
      const int ownHi = split ? ownLo + pieces.GetOwnRows() - 1 : points[1] - 1;
      if (piece.rows[0] != ownLo || piece.rows[1] != ownHi) {
        say << "gives rank " << rank << " the rows " << piece.rows[0] << " to " << piece.rows[1]
            << ", and this run gives it " << ownLo << " to " << ownHi
            << "; restart with the terrain and ranks it was written with";
      } else {
        say << ReadPieceState(piece, folder, bytes);
      }
    }
    why = say.str();
  }
  if (why.empty() && sentence.empty() && !this->LoadState(bytes)) {
    why = "holds a state that this simulation does not take (a damaged piece, or one saved "
          "with other inputs or properties); restart with an intact checkpoint and the inputs "
          "and properties it was written with";
  }
  const bool failed = pieces.AnyRank(!why.empty() || !sentence.empty());
  if (failed && !sentence.empty()) {
    vtkErrorMacro(<< sentence);
    return 0;
  }
  if (failed) {
    vtkErrorMacro(<< subject << " "
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
