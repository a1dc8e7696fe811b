#include "GraupelPieces.h"

#include "vtkCommunicator.h"
#include "vtkExtentTranslator.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/runtime.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace graupel {

namespace {
// Message tags, clear of the controller's RMI tags (1-4) and ParaView's own.
constexpr int TagHalo = 41710;
constexpr int TagRowCount = 41720;
constexpr int TagRows = 41730;

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
} // namespace

bool Pieces::Plan(vtkInformation *outInfo, int ring) {
  this->Split = false;
  this->Controller = vtkMultiProcessController::GetGlobalController();
  this->Size = this->Controller ? this->Controller->GetNumberOfProcesses() : 1;
  this->Rank = this->Controller ? this->Controller->GetLocalProcessId() : 0;
  this->Ring = ring;
  std::fill(this->ExchangeSeconds, this->ExchangeSeconds + 4, 0.0);
  this->ExchangeCalls = 0;
  this->Signature.assign(1, 0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  int whole[6];
  if (!outInfo || !outInfo->Has(SDDP::WHOLE_EXTENT())) {
    return false;
  }
  outInfo->Get(SDDP::WHOLE_EXTENT(), whole);
  this->NX = whole[1] - whole[0] + 1;
  this->NY = whole[3] - whole[2] + 1;
  this->WholeLo = 0;
  this->WholeHi = this->NY - 1;
  const int piece =
      outInfo->Has(SDDP::UPDATE_PIECE_NUMBER()) ? outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()) : 0;
  const int pieces = outInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES())
                         ? outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES())
                         : 1;
  // Only a request of one piece per rank is a parallel update that every
  // rank makes at once; anything else (a pipeline inside one rank) runs
  // whole there, without a message.
  if (ring <= 0 || this->Size < 2 || pieces != this->Size || piece != this->Rank) {
    return false;
  }
  // Every rank's strip, from the translator the executive used (the same
  // on every rank: no message needed).
  const int mode = outInfo->Has(vtkExtentTranslator::UPDATE_SPLIT_MODE())
                       ? outInfo->Get(vtkExtentTranslator::UPDATE_SPLIT_MODE())
                       : vtkExtentTranslator::BLOCK_MODE;
  vtkNew<vtkExtentTranslator> translator;
  std::vector<int> first(static_cast<size_t>(pieces) + 1, this->NY);
  bool fits = true;
  for (int q = 0; q < pieces && fits; ++q) {
    int e[6];
    translator->PieceToExtentThreadSafe(q, pieces, 0, whole, e, mode, 0);
    fits = e[0] == whole[0] && e[1] == whole[1] && e[2] <= e[3];
    first[static_cast<size_t>(q)] = e[2] - whole[2];
    fits = fits && (q == 0 ? first[0] == 0 : first[q] > first[q - 1]);
  }
  for (int q = 0; q < pieces && fits; ++q) {
    // Each strip at least a ring wide toward its neighbours (the core's rule).
    fits = first[q + 1] - first[q] >= ring;
  }
  // The requested rows within this rank's own rows and its neighbours' (a
  // request with ghost levels reaches into them).
  int request[6];
  if (fits && outInfo->Has(SDDP::UPDATE_EXTENT())) {
    outInfo->Get(SDDP::UPDATE_EXTENT(), request);
    const int lo = request[2] - whole[2], hi = request[3] - whole[2];
    const int reachLo = piece > 0 ? first[piece - 1] : 0;
    const int reachHi = piece + 2 <= pieces ? first[piece + 2] - 1 : this->NY - 1;
    fits = lo >= reachLo && hi <= reachHi && lo <= hi;
  }
  // Every rank splits or none does.
  double bad = fits ? 0.0 : 1.0, all = 0.0;
  this->Controller->AllReduce(&bad, &all, 1, vtkCommunicator::MAX_OP);
  if (all != 0.0) {
    return false;
  }
  this->Split = true;
  this->OwnLo = first[piece];
  this->OwnHi = first[piece + 1] - 1;
  this->RingSouth = piece > 0 ? ring : 0;
  this->RingNorth = piece + 1 < pieces ? ring : 0;
  this->Signature = {1, this->Rank, this->Size, this->OwnLo, this->OwnHi, ring, this->NX, this->NY};
  return true;
}

int Pieces::GetLocalRows() const {
  return this->Split ? this->OwnHi - this->OwnLo + 1 + this->RingSouth + this->RingNorth : this->NY;
}

vtkIdType Pieces::GetPieceCells() const {
  return static_cast<vtkIdType>(this->NX) * this->GetLocalRows();
}

void Pieces::PieceGrid(gr_grid *grid) const {
  if (!this->Split) {
    return;
  }
  grid->global_nx = grid->nx;
  grid->global_ny = grid->ny;
  grid->i0 = 0;
  grid->j0 = this->OwnLo;
  grid->ny = this->OwnHi - this->OwnLo + 1;
  grid->ghost = this->Ring;
}

std::vector<float> Pieces::LocalField(const float *whole, int nx, int components) const {
  const size_t row = static_cast<size_t>(nx) * static_cast<size_t>(components);
  const size_t first = static_cast<size_t>(this->GetLocalFirstRow());
  const size_t rows = static_cast<size_t>(this->GetLocalRows());
  return std::vector<float>(whole + first * row, whole + (first + rows) * row);
}

void Pieces::BindHalo(std::function<gr_status(int, size_t *)> size,
                      std::function<gr_status(int, void *, size_t)> get,
                      std::function<gr_status(int, const void *, size_t)> set) {
  this->HaloSize = std::move(size);
  this->HaloGet = std::move(get);
  this->HaloSet = std::move(set);
}

bool Pieces::Swap(int other, const unsigned char *send, vtkIdType sendBytes, unsigned char *recv,
                  vtkIdType recvBytes, int tag) {
  // Blocking sends: the lower rank of a pair sends first, the higher
  // receives first, and Exchange/Rows take their pairs in an order every
  // rank agrees on, so no cycle of ranks waits on each other.
  vtkMultiProcessController *c = this->Controller;
  const bool lower = this->Rank < other;
  int ok = 1;
  if (lower) {
    ok = (!sendBytes || c->Send(send, sendBytes, other, tag)) &&
         (!recvBytes || c->Receive(recv, recvBytes, other, tag));
  } else {
    ok = (!recvBytes || c->Receive(recv, recvBytes, other, tag)) &&
         (!sendBytes || c->Send(send, sendBytes, other, tag));
  }
  return ok != 0;
}

bool Pieces::SwapCounts(int other, int send, int *recv, int tag) {
  vtkMultiProcessController *c = this->Controller;
  int ok = 1;
  if (this->Rank < other) {
    ok = c->Send(&send, 1, other, tag) && c->Receive(recv, 1, other, tag);
  } else {
    ok = c->Receive(recv, 1, other, tag) && c->Send(&send, 1, other, tag);
  }
  return ok != 0;
}

gr_status Pieces::Exchange(void *user) {
  auto *self = static_cast<Pieces *>(user);
  if (!self->Split) {
    return GR_OK;
  }
  const double t0 = Now();
  double t1 = t0;
  // Strips along y: only south and north neighbours (x sides would come
  // first, as the cores ask). Pairs (even, odd) first, then (odd, even).
  const int order[2] = {self->Rank % 2 == 0 ? NORTH : SOUTH, self->Rank % 2 == 0 ? SOUTH : NORTH};
  for (const int side : order) {
    const int other = side == NORTH ? self->Rank + 1 : self->Rank - 1;
    if (other < 0 || other >= self->Size) {
      continue;
    }
    size_t bytes = 0;
    gr_status st = self->HaloSize(side, &bytes);
    if (st != GR_OK) {
      return st;
    }
    self->SendBuffer.resize(bytes);
    self->ReceiveBuffer.resize(bytes);
    st = self->HaloGet(side, self->SendBuffer.data(), bytes);
    if (st != GR_OK) {
      return st;
    }
    const double t2 = Now();
    self->ExchangeSeconds[1] += t2 - t1;
    const vtkIdType n = static_cast<vtkIdType>(bytes);
    if (!self->Swap(other, self->SendBuffer.data(), n, self->ReceiveBuffer.data(), n, TagHalo)) {
      return GR_ERR_ABORTED;
    }
    const double t3 = Now();
    self->ExchangeSeconds[2] += t3 - t2;
    st = self->HaloSet(side, self->ReceiveBuffer.data(), bytes);
    if (st != GR_OK) {
      return st;
    }
    t1 = Now();
    self->ExchangeSeconds[3] += t1 - t3;
  }
  self->ExchangeSeconds[0] += Now() - t0;
  ++self->ExchangeCalls;
  return GR_OK;
}

gr_status Pieces::Allreduce(void *user, double *values, int n, gr_reduce_op op) {
  auto *self = static_cast<Pieces *>(user);
  if (!self->Split || n <= 0) {
    return GR_OK;
  }
  // Gathered on rank 0, combined there in rank order, broadcast: every rank
  // gets the same bits, whatever MPI's own reduction order would be.
  vtkMultiProcessController *c = self->Controller;
  std::vector<double> all(static_cast<size_t>(n) * static_cast<size_t>(self->Size));
  if (!c->Gather(values, all.data(), n, 0)) {
    return GR_ERR_ABORTED;
  }
  if (self->Rank == 0) {
    for (int q = 0; q < n; ++q) {
      double v = all[static_cast<size_t>(q)];
      for (int r = 1; r < self->Size; ++r) {
        const double w = all[static_cast<size_t>(r) * static_cast<size_t>(n) + q];
        v = op == GR_REDUCE_SUM ? v + w : op == GR_REDUCE_MAX ? std::max(v, w) : std::min(v, w);
      }
      values[q] = v;
    }
  }
  return c->Broadcast(values, n, 0) ? GR_OK : GR_ERR_ABORTED;
}

bool Pieces::AnyRank(bool flag) {
  if (!this->Split) {
    return flag;
  }
  double v = flag ? 1.0 : 0.0;
  Allreduce(this, &v, 1, GR_REDUCE_MAX);
  return v != 0.0;
}

bool Pieces::Rows(const float *own, int nx, int components, int lo, int hi, std::vector<float> &out,
                  std::string &error) {
  const size_t row = static_cast<size_t>(nx) * static_cast<size_t>(components);
  out.assign(static_cast<size_t>(hi - lo + 1) * row, 0.0f);
  if (!this->Split) {
    std::copy(own + static_cast<size_t>(lo) * row, own + static_cast<size_t>(hi + 1) * row,
              out.begin());
    return true;
  }
  const int ownRows = this->OwnHi - this->OwnLo + 1;
  // What each side needs of the other: rows below OwnLo come from the
  // southern neighbour's top, rows above OwnHi from the northern one's bottom.
  const int needSouth = std::max(0, this->OwnLo - lo);
  const int needNorth = std::max(0, hi - this->OwnHi);
  const int order[2] = {this->Rank % 2 == 0 ? NORTH : SOUTH, this->Rank % 2 == 0 ? SOUTH : NORTH};
  for (const int side : order) {
    const int other = side == NORTH ? this->Rank + 1 : this->Rank - 1;
    const int need = side == NORTH ? needNorth : needSouth;
    if (other < 0 || other >= this->Size) {
      if (need > 0) {
        error = "rows beyond the grid's edge were asked for";
        return false;
      }
      continue;
    }
    int give = 0;
    if (!this->SwapCounts(other, need, &give, TagRowCount)) {
      error = "a message to a neighbouring rank failed";
      return false;
    }
    if (give > ownRows || give < 0) {
      error = "a neighbouring rank asked for more rows than this rank holds";
      return false;
    }
    // To the north: my top rows; to the south: my bottom rows.
    const size_t from = side == NORTH ? static_cast<size_t>(ownRows - give) : 0;
    const unsigned char *send = reinterpret_cast<const unsigned char *>(own + from * row);
    std::vector<float> got(static_cast<size_t>(need) * row);
    const vtkIdType bytes = static_cast<vtkIdType>(sizeof(float) * row);
    if (!this->Swap(other, send, give * bytes, reinterpret_cast<unsigned char *>(got.data()),
                    need * bytes, TagRows)) {
      error = "a message to a neighbouring rank failed";
      return false;
    }
    // The neighbour's rows nearest to this strip, in grid order.
    const int at = side == NORTH ? this->OwnHi + 1 : lo;
    std::copy(got.begin(), got.end(), out.begin() + static_cast<size_t>(at - lo) * row);
  }
  const int a = std::max(lo, this->OwnLo), b = std::min(hi, this->OwnHi);
  if (a <= b) {
    std::copy(own + static_cast<size_t>(a - this->OwnLo) * row,
              own + static_cast<size_t>(b - this->OwnLo + 1) * row,
              out.begin() + static_cast<size_t>(a - lo) * row);
  }
  return true;
}

namespace {
// The local rank of a multi-process run as the MPI launchers name it; the
// global rank where none does (one node).
int LocalRank(vtkMultiProcessController *c) {
  for (const char *name : {"OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID",
                           "MV2_COMM_WORLD_LOCAL_RANK", "SLURM_LOCALID", "PMI_LOCAL_RANK"}) {
    const char *v = std::getenv(name);
    if (v && *v) {
      return std::atoi(v);
    }
  }
  return c->GetLocalProcessId();
}

bool Opens(const std::string &request) {
  gr_context_options opt;
  gr_context_options_init(&opt);
  opt.device = request.c_str();
  gr_context *ctx = nullptr;
  if (gr_context_acquire(&opt, &ctx) != GR_OK) {
    return false;
  }
  gr_context_release(ctx);
  return true;
}
} // namespace

std::string RankDeviceRequest(const char *device) {
  const std::string given = device ? device : "";
  vtkMultiProcessController *c = vtkMultiProcessController::GetGlobalController();
  if (!c || c->GetNumberOfProcesses() < 2) {
    return given;
  }
  const int local = LocalRank(c);
  std::string base = given;
  if (base.empty() || base == "auto") {
    const char *env = std::getenv("GRAUPEL_DEVICE");
    base = env && *env ? env : "auto";
  }
  const size_t colon = base.rfind(':');
  const bool indexed = colon != std::string::npos && colon + 1 < base.size() &&
                       base.find_first_not_of("0123456789", colon + 1) == std::string::npos;
  if (local <= 0 || indexed) {
    return given;
  }
  // The number of devices the request matches: the first index that opens,
  // counting down from the local rank's (PoCL has one CPU device: every
  // rank shares it).
  int count = 0;
  for (int d = local + 1; d >= 1 && count == 0; --d) {
    if (Opens(base + ":" + std::to_string(d - 1))) {
      count = d;
    }
  }
  if (count == 0) {
    return given; // no device at all: the usual sentence follows
  }
  return base + ":" + std::to_string(local % count);
}

} // namespace graupel
