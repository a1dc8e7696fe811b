// Private to Filters/: a grid simulation split over the ranks of an MPI run
// (vtkMultiProcessController::GetGlobalController()), for the cores that
// follow the piece/halo contract (graupel.h's gr_grid piece fields, the
// cores' "Pieces of a split domain").
//
// The split: strips along y, one per rank, taken from the pipeline's own
// piece request (vtkGraupelSimulation asks for Y_SLAB_MODE, so rank r's
// requested extent is its strip plus the row it shares with the next one).
// Rank r owns the rows from its strip's first to the row before the next
// strip's first, and keeps a ring of `ring` rows toward each neighbouring
// strip (the core's ghost), refreshed by Exchange. The output's rows that
// a rank does not own (the shared row, ghost levels) come from the
// neighbour once per output (Rows), never the whole grid.
//
// When the request is not one piece per rank (a local pipeline inside one
// rank, a different piece count) or a strip would be narrower than the
// ring, Plan says so and the simulation keeps its old behaviour: every rank
// simulates the whole grid and crops what was asked. The decision is the
// same on every rank (reduced), so ranks never disagree about collective
// calls.
//
// Collectives (Exchange, Allreduce, AnyRank, Rows) must be called by every
// rank in the same order; they combine in rank order, so every rank gets
// the same bits. With one process, no MPI or no split, they do nothing.
#ifndef GraupelPieces_h
#define GraupelPieces_h

#include "vtkType.h"

#include "graupel/graupel.h"

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

class vtkInformation;
class vtkMultiProcessController;

namespace graupel {

class Pieces {
public:
  /** Sides, as every core numbers them (gr_*_side). */
  enum Side { WEST = 0, EAST = 1, SOUTH = 2, NORTH = 3 };

  /**
   * Decides the layout for the request in outInfo (UPDATE_PIECE_NUMBER,
   * UPDATE_NUMBER_OF_PIECES, UPDATE_EXTENT, WHOLE_EXTENT). ring: the core's
   * ghost width (0: the core cannot run as pieces). Collective when the
   * request is one piece per rank of a multi-process run. Returns whether
   * this rank simulates a strip.
   */
  bool Plan(vtkInformation *outInfo, int ring);

  bool IsSplit() const { return this->Split; }
  int GetRank() const { return this->Rank; }
  int GetNumberOfRanks() const { return this->Size; }
  /** What the state depends on: changes when the layout does. */
  const std::vector<int> &GetSignature() const { return this->Signature; }

  /**
   * The core's grid of this rank: whole (the whole grid unchanged) fills
   * the piece fields (ny, j0, global_nx, global_ny, ghost) when split.
   */
  void PieceGrid(gr_grid *grid) const;

  /** First row (grid index) and number of rows of the local arrays: own rows and ring. */
  int GetLocalFirstRow() const { return this->Split ? this->OwnLo - this->RingSouth : 0; }
  int GetLocalRows() const;
  /** Grid points this rank simulates, ring included. */
  vtkIdType GetPieceCells() const;

  /**
   * The local array (own rows and ring) of a whole-grid field of nx points a
   * row and `components` values a point; the field itself when not split.
   */
  std::vector<float> LocalField(const float *whole, int nx, int components) const;

  /**
   * The core's halo calls for this rank: size(side, &bytes), get(side, host,
   * bytes) and set(side, host, bytes), as gr_<core>_halo_size/get/set.
   */
  void BindHalo(std::function<gr_status(int, size_t *)> size,
                std::function<gr_status(int, void *, size_t)> get,
                std::function<gr_status(int, const void *, size_t)> set);

  /** gr_halo_exchange_fn and gr_allreduce_fn over the ranks; user is the Pieces. */
  static gr_status Exchange(void *user);
  static gr_status Allreduce(void *user, double *values, int n, gr_reduce_op op);

  /** Whether flag is non-zero on any rank (every rank gets the answer); flag itself unsplit. */
  bool AnyRank(bool flag);

  /**
   * Rows lo..hi (grid indices, lo >= 0) of a field, nx points a row, from
   * own (this rank's own rows, nx x own rows x components): rows this rank
   * does not own come from the neighbours (at most their own rows away).
   * Collective. false with a sentence in error when a row is out of reach
   * or a message fails.
   */
  bool Rows(const float *own, int nx, int components, int lo, int hi, std::vector<float> &out,
            std::string &error);

  /** Own rows: first (grid index) and count. */
  int GetOwnFirstRow() const { return this->OwnLo; }
  int GetOwnRows() const { return this->OwnHi - this->OwnLo + 1; }

  /**
   * Seconds spent in Exchange since the last Plan (part 0), of which reading
   * the strips from the device (1: it waits for the step's kernels), the
   * messages with the waiting for the neighbours (2) and writing the rings
   * (3); and the calls. For timing runs.
   */
  double GetExchangeSeconds(int part = 0) const {
    return part >= 0 && part < 4 ? this->ExchangeSeconds[part] : 0.0;
  }
  long GetExchangeCalls() const { return this->ExchangeCalls; }

private:
  /** Swaps with a neighbour: the lower rank sends first (no cycle of blocking sends). */
  bool Swap(int other, const unsigned char *send, vtkIdType sendBytes, unsigned char *recv,
            vtkIdType recvBytes, int tag);
  bool SwapCounts(int other, int send, int *recv, int tag);

  vtkMultiProcessController *Controller = nullptr;
  bool Split = false;
  int Rank = 0, Size = 1, Ring = 0;
  int WholeLo = 0, WholeHi = 0; // y rows of the whole grid (extent indices)
  int OwnLo = 0, OwnHi = 0;     // this rank's own rows (extent indices)
  int RingSouth = 0, RingNorth = 0;
  int NX = 0, NY = 0; // the whole grid's points
  std::vector<int> Signature;
  std::function<gr_status(int, size_t *)> HaloSize;
  std::function<gr_status(int, void *, size_t)> HaloGet;
  std::function<gr_status(int, const void *, size_t)> HaloSet;
  std::vector<unsigned char> SendBuffer, ReceiveBuffer;
  double ExchangeSeconds[4] = {0.0, 0.0, 0.0, 0.0};
  long ExchangeCalls = 0;
};

/**
 * The device request for this process: `device` (or GRAUPEL_DEVICE, or
 * auto) with ":N" for the local rank N of a multi-process run, wrapped
 * around the devices the request matches (PoCL's one CPU device serves
 * every rank). `device` unchanged with one process, on local rank 0 or
 * when it already names an index.
 */
std::string RankDeviceRequest(const char *device);

} // namespace graupel

#endif
