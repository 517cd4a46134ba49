#include "common/ranks.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <thread>

#ifdef SPECIMEN_HAVE_MPI
#include <mpi.h>
#endif

namespace specimen {

#ifdef SPECIMEN_HAVE_MPI
namespace {

bool active = false;  // MPI started by a RankSession and not finalized
int rank = 0;
int count = 1;
constexpr int kNoteTag = 7001;
std::deque<int> note_buffers;  // stable addresses until CompleteNotes
std::vector<MPI_Request> note_requests;

// Started by a launcher: Open MPI's mpirun, or a PMI/PMIx launcher (MPICH's hydra, Slurm's
// srun). Without one, MPI_Init of Open MPI 4 starts a daemon of its own (a "singleton"):
// seconds of start-up and a runtime that some containers refuse, for a run of one rank.
bool LaunchedByMpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

// Waits for `request` without spinning. Open MPI polls in its blocking calls, one core at
// 100 % per waiting rank: on a shared node (or ranks oversubscribed on fewer cores) a rank
// that reached an exchange first would take the core of a rank still running its points.
void QuietWait(MPI_Request* request) {
  int done = 0;
  auto pause = std::chrono::microseconds(50);
  for (;;) {
    MPI_Test(request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(pause);
    if (pause < std::chrono::milliseconds(5)) pause *= 2;
  }
}

// Every rank has reached this point (then a collective call returns at once).
void QuietBarrier() {
  MPI_Request request;
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  QuietWait(&request);
}

}  // namespace

RankSession::RankSession(int* argc, char*** argv) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized || !LaunchedByMpi()) return;
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &count);
  active = true;
  owner_ = true;
}

RankSession::~RankSession() {
  if (!owner_) return;
  CompleteNotes();
  MPI_Finalize();
  active = false;
  rank = 0;
  count = 1;
}

int Rank() { return rank; }
int RankCount() { return count; }
bool RanksAvailable() { return true; }

void AbortAllRanks(int status) {
  if (active && count > 1) MPI_Abort(MPI_COMM_WORLD, status);
}

std::vector<std::string> AllGather(const std::string& mine) {
  if (!active || count == 1) return {mine};
  QuietBarrier();
  const int size = static_cast<int>(mine.size());
  std::vector<int> sizes(count), offsets(count, 0);
  MPI_Allgather(&size, 1, MPI_INT, sizes.data(), 1, MPI_INT, MPI_COMM_WORLD);
  long long total = 0;
  for (int r = 0; r < count; ++r) {
    offsets[r] = static_cast<int>(total);
    total += sizes[r];
  }
  std::string all(static_cast<size_t>(total), '\0');
  MPI_Allgatherv(mine.data(), size, MPI_CHAR, all.data(), sizes.data(), offsets.data(), MPI_CHAR, MPI_COMM_WORLD);
  std::vector<std::string> out;
  for (int r = 0; r < count; ++r) out.push_back(all.substr(offsets[r], sizes[r]));
  return out;
}

std::string Broadcast(const std::string& text, int root) {
  if (!active || count == 1) return text;
  QuietBarrier();
  long long size = static_cast<long long>(text.size());
  MPI_Bcast(&size, 1, MPI_LONG_LONG, root, MPI_COMM_WORLD);
  std::string out = rank == root ? text : std::string(static_cast<size_t>(size), '\0');
  // In pieces: MPI counts are int (a 2,000,000-particle packing is above 2^31 bytes in text).
  constexpr long long kPiece = 1 << 30;
  for (long long at = 0; at < size; at += kPiece)
    MPI_Bcast(out.data() + at, static_cast<int>(std::min(kPiece, size - at)), MPI_CHAR, root, MPI_COMM_WORLD);
  return out;
}

void SendNoteToRoot(int value) {
  if (!active || count == 1 || rank == 0) return;
  note_buffers.push_back(value);
  note_requests.emplace_back();
  MPI_Isend(&note_buffers.back(), 1, MPI_INT, 0, kNoteTag, MPI_COMM_WORLD, &note_requests.back());
}

std::vector<RankNote> ReceiveNotes() {
  std::vector<RankNote> notes;
  if (!active || count == 1 || rank != 0) return notes;
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kNoteTag, MPI_COMM_WORLD, &arrived, &status);
    if (!arrived) return notes;
    RankNote note;
    note.rank = status.MPI_SOURCE;
    MPI_Recv(&note.value, 1, MPI_INT, status.MPI_SOURCE, kNoteTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    notes.push_back(note);
  }
}

void CompleteNotes() {
  for (MPI_Request& request : note_requests) QuietWait(&request);
  note_requests.clear();
  note_buffers.clear();
}

#else  // one process: the identity

RankSession::RankSession(int*, char***) {}
RankSession::~RankSession() { (void)owner_; }
int Rank() { return 0; }
int RankCount() { return 1; }
bool RanksAvailable() { return false; }
void AbortAllRanks(int) {}
std::vector<std::string> AllGather(const std::string& mine) { return {mine}; }
std::string Broadcast(const std::string& text, int) { return text; }
void SendNoteToRoot(int) {}
std::vector<RankNote> ReceiveNotes() { return {}; }
void CompleteNotes() {}

#endif

bool Distributed() { return RankCount() > 1; }

double Broadcast(double value, int root) {
  if (!Distributed()) return value;
  std::string bytes(sizeof(double), '\0');
  std::memcpy(bytes.data(), &value, sizeof(double));  // the bits, not a decimal rendering
  bytes = Broadcast(bytes, root);
  std::memcpy(&value, bytes.data(), sizeof(double));
  return value;
}

}  // namespace specimen
