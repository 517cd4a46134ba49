#pragma once
// The ranks of a distributed run: MPI over MPI_COMM_WORLD when the toolkit was built with MPI
// (CMake found it) and the program was started by an MPI launcher (mpirun -n N); one rank
// otherwise, where every call below is the identity and costs nothing.
//
// The programs are SPMD: every rank runs the same code on the same inputs and takes the same
// decisions; only measurements are split over the ranks and exchanged (AllGather), and
// inputs that one rank makes (generated packings) are sent to the others (Broadcast). Only
// the thread that created the RankSession calls these functions (MPI_THREAD_FUNNELED); the
// worker threads of a rank never do.
//
//   int main(int argc, char** argv) {
//     RankSession session(&argc, &argv);
//     std::vector<std::string> all = AllGather(my_results_as_json);  // rank order
//   }

#include <string>
#include <vector>

namespace specimen {

// MPI_Init_thread / MPI_Finalize, once per process (the first session only; others are
// inert). MPI is started only when a launcher started the process (its environment says
// so): the same binary run on its own stays a plain process, with no MPI runtime started.
class RankSession {
 public:
  RankSession(int* argc, char*** argv);
  ~RankSession();
  RankSession(const RankSession&) = delete;
  RankSession& operator=(const RankSession&) = delete;

 private:
  bool owner_ = false;
};

int Rank();          // 0 when not distributed
int RankCount();     // 1 when not distributed
bool Distributed();  // RankCount() > 1
// Built with MPI (a launched program can then have several ranks).
bool RanksAvailable();

// Ends every rank of the job with `status`: after a failure on one rank the others may be
// waiting for it in an exchange, and would wait for ever. Returns (does nothing) on one rank.
void AbortAllRanks(int status);

// Every rank's `mine`, in rank order (collective: every rank calls it).
std::vector<std::string> AllGather(const std::string& mine);
// `root`'s `text` on every rank (collective).
std::string Broadcast(const std::string& text, int root = 0);
double Broadcast(double value, int root = 0);

// Small notes to rank 0 while the ranks work (the progress of a sweep): SendNoteToRoot does
// not wait for rank 0 to receive it; ReceiveNotes returns those arrived at rank 0 so far.
// Notes from one rank arrive in the order sent. CompleteNotes waits until this rank's notes
// have left (before the next exchange).
struct RankNote {
  int rank = 0;
  int value = 0;
};
void SendNoteToRoot(int value);
std::vector<RankNote> ReceiveNotes();
void CompleteNotes();

}  // namespace specimen
