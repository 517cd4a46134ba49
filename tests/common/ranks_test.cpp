// common/ranks.h without a launcher: one rank, every exchange the identity (the programs run
// as they did before MPI). The distributed behaviour is tested under mpirun by
// tests/tools/mpi_sweep_test.py.
#include "common/ranks.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

namespace specimen {
namespace {

TEST(Ranks, WithoutALauncherThereIsOneRankAndExchangesAreTheIdentity) {
  int argc = 1;
  char name[] = "ranks_test";
  char* args[] = {name, nullptr};
  char** argv = args;
  RankSession session(&argc, &argv);  // ctest starts no MPI launcher: no MPI runtime
  EXPECT_EQ(Rank(), 0);
  EXPECT_EQ(RankCount(), 1);
  EXPECT_FALSE(Distributed());
  EXPECT_EQ(AllGather("abc"), std::vector<std::string>{"abc"});
  EXPECT_EQ(Broadcast(std::string("text\0with nul", 13)), std::string("text\0with nul", 13));
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(Broadcast(tiny), tiny);
  SendNoteToRoot(3);
  EXPECT_TRUE(ReceiveNotes().empty());
  CompleteNotes();
  AbortAllRanks(2);  // one rank: returns
}

}  // namespace
}  // namespace specimen
