// InUserTerms: the library's field names in a message become the names the user typed.
#include <gtest/gtest.h>

#include "common/field_names.h"

namespace {

using specimen::FieldNames;
using specimen::InUserTerms;

TEST(InUserTerms, ReplacesEveryWholeWordOccurrence) {
  const FieldNames names = {{"node_size_spread", "--node-spread"}, {"radius_ratio", "--radius-ratio"}};
  EXPECT_EQ(InUserTerms("node_size_spread = 20 is not allowed: it must be in [1, radius_ratio = 10]", names),
            "--node-spread = 20 is not allowed: it must be in [1, --radius-ratio = 10]");
}

TEST(InUserTerms, LeavesLongerIdentifiersAlone) {
  // "normal_stiffness" inside "wall_normal_stiffness" or "normal_stiffness_n" is another field.
  const FieldNames names = {{"normal_stiffness", "kn"}};
  EXPECT_EQ(InUserTerms("wall_normal_stiffness and normal_stiffness_n and normal_stiffness", names),
            "wall_normal_stiffness and normal_stiffness_n and kn");
}

TEST(InUserTerms, AReplacementContainingTheFieldDoesNotLoop) {
  const FieldNames names = {{"threads", "--threads (or [test] threads)"}};
  EXPECT_EQ(InUserTerms("threads = 0", names), "--threads (or [test] threads) = 0");
}

TEST(InUserTerms, NoNamesNoChange) {
  EXPECT_EQ(InUserTerms("mean_radius = -1", {}), "mean_radius = -1");
}

}  // namespace
