// The progressive mesh's corner lists (progressive.h: StarPool).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "progressive.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

// The star pool against plain vectors: stars that grow through many block sizes, removals,
// vertices popped and added again (their blocks reused), in random order.
TEST(StarPool, StarPoolKeepsEveryListExactly) {
  StarPool pool;
  std::vector<std::vector<uint32_t>> ref;
  std::mt19937 rng(7);
  for (int step = 0; step < 200000; ++step) {
    const uint32_t r = rng() % 100;
    if (ref.empty() || r < 3) {
      ref.emplace_back();
      ASSERT_EQ(pool.addVertex(rng() % 40), ref.size() - 1);
    } else if (r < 5 && ref.size() > 1) {
      pool.popVertex();
      ref.pop_back();
    } else if (r < 10) {
      const uint32_t v = rng() % ref.size(), m = rng() % 5;
      pool.removeIf(v, [&](uint32_t c) { return c % 5 == m; });
      std::erase_if(ref[v], [&](uint32_t c) { return c % 5 == m; });
    } else {
      // Skewed: a few vertices get long lists (hundreds of corners, many growth steps).
      const uint32_t v = (r < 40 ? rng() % std::min<size_t>(ref.size(), 3) : rng() % ref.size());
      const uint32_t c = rng();
      pool.add(v, c);
      ref[v].push_back(c);
    }
  }
  ASSERT_EQ(pool.vertexCount(), ref.size());
  size_t longest = 0;
  for (uint32_t v = 0; v < ref.size(); ++v) {
    auto got = pool.corners(v);
    std::vector<uint32_t> a(got.begin(), got.end()), b = ref[v];
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a, b) << "vertex " << v;
    longest = std::max(longest, b.size());
  }
  EXPECT_GT(longest, 1000u);  // the growth path was exercised
}
