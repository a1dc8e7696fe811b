#include "GraupelRemoteAbort.h"

#include "vtkCallbackCommand.h"
#include "vtkClientSocket.h"
#include "vtkCommand.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkSocketCommunicator.h"
#include "vtkWeakPointer.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <poll.h>
#include <sys/socket.h>
#define GRAUPEL_HAVE_POLL 1
#else
#define GRAUPEL_HAVE_POLL 0
#endif

namespace graupel {
namespace {

ClientLookup Lookup = nullptr;
// The communicator whose WrongTagEvent we observe (ParaView's server has one client).
vtkWeakPointer<vtkSocketCommunicator> Observed;
// While RemoteAbortAsked reads up to the abort, the messages before it are buffered.
bool Reading = false;
// An abort holds for the update of HoldWho at HoldTime (see the header).
bool Holding = false;
const void *HoldWho = nullptr;
double HoldTime = 0.0;
// When the last progress bracket ended (steady clock, s).
double LastEnd = -1e300;

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void OnWrongTag(vtkObject *caller, unsigned long, void *clientData, void *callData) {
  auto *command = static_cast<vtkCallbackCommand *>(clientData);
  int tag = 0;
  std::memcpy(&tag, callData, sizeof(tag));
  if (tag == RemoteAbortTag) {
    // An abort that came after its update ended (or a second one): dropped.
    command->SetAbortFlag(1);
  } else if (Reading) {
    // Kept for ParaView's server loop, which empties the buffer first.
    static_cast<vtkSocketCommunicator *>(caller)->BufferCurrentMessage();
    command->SetAbortFlag(1);
  }
}

void Observe(vtkSocketCommunicator *comm) {
  if (Observed == comm) {
    return;
  }
  vtkNew<vtkCallbackCommand> command;
  command->SetCallback(OnWrongTag);
  command->SetClientData(command.GetPointer());
  // Ahead of ParaView's session, which reports an unknown tag as an error.
  comm->AddObserver(vtkCommand::WrongTagEvent, command, 100.0f);
  Observed = comm;
}

vtkSocketCommunicator *SocketOf(vtkMultiProcessController *c) {
  return c ? vtkSocketCommunicator::SafeDownCast(c->GetCommunicator()) : nullptr;
}

} // namespace

void SetClientLookup(ClientLookup lookup) {
  Lookup = lookup;
}

bool SendRemoteAbort(vtkMultiProcessController *toServer) {
  vtkSocketCommunicator *comm = SocketOf(toServer);
  if (!comm || !comm->GetIsConnected()) {
    return false;
  }
  int one = 1;
  return comm->Send(&one, 1, 1, RemoteAbortTag) != 0;
}

void BeginRemoteRequest() {
  if (Now() - LastEnd > 1.0) {
    Holding = false; // the client was quiet: a new step of the user's
  }
}

void EndRemoteRequest() {
  LastEnd = Now();
}

namespace {
// The client's socket: closed (true in *gone), or an abort waiting (read).
bool Poll(bool *gone);
} // namespace

bool RemoteAbortAsked(const void *who, double time, bool starting) {
  bool gone = false;
  const bool asked = Poll(&gone);
  if (gone) {
    return true;
  }
  if (asked && !starting) {
    Holding = true;
    HoldWho = who;
    HoldTime = time;
  }
  return (asked && !starting) || (Holding && HoldWho == who && HoldTime == time);
}

namespace {
bool Poll(bool *gone) {
#if GRAUPEL_HAVE_POLL
  vtkSocketCommunicator *comm = Lookup ? SocketOf(Lookup()) : nullptr;
  vtkClientSocket *socket = comm ? comm->GetSocket() : nullptr;
  if (!socket || !socket->GetConnected()) {
    return false;
  }
  Observe(comm);
  pollfd p{socket->GetSocketDescriptor(), POLLIN, 0};
  if (poll(&p, 1, 0) <= 0) {
    return false;
  }
  if (p.revents & (POLLHUP | POLLERR)) {
    *gone = true; // nobody waits for this update
    return false;
  }
  // Look at what waits without taking it: ParaView's messages are a tag, a
  // length and that many bytes.
  std::vector<char> bytes(size_t(1) << 16);
  const ssize_t n = recv(p.fd, bytes.data(), bytes.size(), MSG_PEEK | MSG_DONTWAIT);
  if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
    *gone = true; // closed by the client
    return false;
  }
  if (n < 0) {
    return false;
  }
  // 1 is the communicator's (private) SwapOn: the two ends differ in byte order.
  const bool swap = comm->GetSwapBytesInReceivedData() == 1;
  auto word = [&bytes, swap](size_t at) {
    unsigned char b[4];
    std::memcpy(b, bytes.data() + at, 4);
    if (swap) {
      std::swap(b[0], b[3]);
      std::swap(b[1], b[2]);
    }
    int v = 0;
    std::memcpy(&v, b, 4);
    return v;
  };
  bool found = false;
  for (size_t at = 0; at + 8 <= static_cast<size_t>(n);) {
    const int tag = word(at), length = word(at + 4);
    if (tag == RemoteAbortTag) {
      found = true;
      break;
    }
    if (length < 0) {
      break;
    }
    at += 8 + static_cast<size_t>(length);
  }
  if (!found) {
    return false;
  }
  int one = 0;
  Reading = true;
  const int ok = comm->Receive(&one, 1, 1, RemoteAbortTag);
  Reading = false;
  return ok != 0;
#else
  (void)gone;
  return false;
#endif
}
} // namespace

} // namespace graupel
