// The collapse log (pack/collapse_log.h): the tets of each collapse read back as written.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "pack/collapse_log.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

// The collapse log keeps each collapse's tets as varints (collapse_log.h): read back, they must
// be what was written (moved tets as a set), for ids anywhere in uint32, empty lists included,
// and a record copied into another log must read the same there.
TEST(CollapseLog, TetsReadBackAsWrittenAndCopied) {
  std::mt19937 rng(7);
  auto id = [&] {
    switch (rng() % 4) {
      case 0: return uint32_t(rng() % 16);
      case 1: return ~uint32_t(0) - uint32_t(rng() % 16);
      default: return uint32_t(rng());
    }
  };
  CollapseLog log, copy;
  std::vector<CollapseTets> written;
  for (int c = 0; c < 500; ++c) {
    CollapseTets t;
    for (uint32_t k = rng() % 20; k-- > 0;) t.moved.push_back(id());
    for (uint32_t k = rng() % 8; k-- > 0;) t.removed.push_back(id());
    for (size_t k = 0; k < 2 * t.removed.size(); ++k) t.others.push_back(id());
    const uint32_t j = id();
    log.i.push_back(id());
    log.j.push_back(j);
    written.push_back(t);
    log.appendTets(t, j);
    std::sort(written.back().moved.begin(), written.back().moved.end());
  }
  for (uint32_t c = 0; c < log.size(); ++c) {  // (record c of the open log ends at tetBytes.size())
    copy.i.push_back(log.i[c]);
    copy.j.push_back(log.j[c]);
    copy.appendTetsOf(log, c);
  }
  log.close(false);
  copy.close(false);
  EXPECT_EQ(copy.tetBytes, log.tetBytes);
  CollapseTets read;
  for (uint32_t c = 0; c < log.size(); ++c) {
    for (const CollapseLog* l : {&log, &copy}) {
      l->readTets(c, read);
      EXPECT_EQ(read.moved, written[c].moved) << c;
      EXPECT_EQ(read.removed, written[c].removed) << c;
      EXPECT_EQ(read.others, written[c].others) << c;
    }
  }
}
