// Regular packings built in code: the particle and contact counts of Madan's specimens.

#include "solver/regular_lattice.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"

namespace specimen {
namespace {

TEST(RegularLattice, MadanSquareSpecimen) {
  const Packing<2> p = SquareLatticePacking(9, 20, 1e-3);
  EXPECT_EQ(p.size(), 180);
  EXPECT_EQ(p.contacts.size(), 9u * 19 + 8u * 20);            // 331
  EXPECT_EQ(p.centres[19 * 9 + 8], Vector<2>(16e-3, 38e-3));  // centre spans 16 x 38 mm
  for (const auto& c : p.contacts) EXPECT_NEAR(p.Gap(c[0], c[1]), 0.0, 1e-15);
}

TEST(RegularLattice, MadanHexagonalSpecimen) {
  const Packing<2> p = HexagonalLatticePacking(17, 6, 7, 1e-3);
  EXPECT_EQ(p.size(), 110);  // 9 x 6 + 8 x 7
  // Rows: 9 x 5 + 8 x 6 horizontal, 16 interfaces x 12 diagonal contacts.
  EXPECT_EQ(p.contacts.size(), 45u + 48u + 16u * 12u);
  // Centre spans H = 16 sqrt(3) R = 27.71 mm, A = 12 mm (the 7-disc rows).
  EXPECT_NEAR(p.centres.back().y() - p.centres.front().y(), 16 * std::sqrt(3.0) * 1e-3, 1e-15);
  EXPECT_NEAR(p.centres[6 + 6].x() - p.centres[6].x(), 12e-3, 1e-15);
  for (const auto& c : p.contacts) EXPECT_NEAR(p.Gap(c[0], c[1]), 0.0, 1e-15);
}

TEST(RegularLattice, CubicBlockAndBadInput) {
  const Packing<3> p = CubicLatticePacking(3, 3, 5, 1e-3);
  EXPECT_EQ(p.size(), 45);
  EXPECT_EQ(p.contacts.size(), 2u * 3 * 5 + 3u * 2 * 5 + 3u * 3 * 4);
  EXPECT_THROW(SquareLatticePacking(0, 3, 1e-3), InputError);
  EXPECT_THROW(HexagonalLatticePacking(3, 3, 3, -1.0), InputError);
}

}  // namespace
}  // namespace specimen
