// The simplifier's work pool (pack/work_pool.h).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "pack/work_pool.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

// Every task of every round runs exactly once, whether the helper takes part or is held up
// (a helper stuck in a slow task must not make the caller run a task twice or skip one).
TEST(WorkPool, WorkPoolRunsEveryTaskOnce) {
  WorkPool pool(1);
  std::vector<std::atomic<int>> runs(8);
  for (int round = 0; round < 20000; ++round) {
    const uint32_t n = 1 + uint32_t(round % 8);
    for (auto& r : runs) r.store(0);
    pool.run(n, [&](uint32_t k) {
      if (round % 1000 == 7 && k == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      runs[k].fetch_add(1);
    });
    for (uint32_t k = 0; k < 8; ++k) ASSERT_EQ(runs[k].load(), k < n ? 1 : 0) << "round " << round << " task " << k;
  }
}
