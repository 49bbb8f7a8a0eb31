// Brick-ordered launches (core/brick_order.h) visit every voxel of a grid exactly once, whatever
// the grid's dims, and nothing past its edges.
#include <vector>

#include <gtest/gtest.h>

#include "core/brick_order.h"

using namespace visopt;

TEST(BrickOrder, VisitsEveryVoxelOnce) {
  for (glm::ivec3 dims :
       {glm::ivec3(1, 1, 1), glm::ivec3(8, 8, 8), glm::ivec3(13, 9, 17), glm::ivec3(64, 3, 1)}) {
    const BrickOrder order(dims);
    std::vector<int> visits(size_t(dims.x) * dims.y * dims.z, 0);
    for (int64_t n = 0; n < order.launches(); ++n) {
      int i, j, k;
      if (!order.voxel(n, i, j, k)) continue;
      ASSERT_TRUE(i >= 0 && j >= 0 && k >= 0);
      ++visits[(size_t(k) * dims.y + j) * dims.x + i];
    }
    for (int v : visits) ASSERT_EQ(v, 1);
  }
}
