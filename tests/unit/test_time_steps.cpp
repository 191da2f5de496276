// Choosing the time step of a file with several (--step, --time, default the last).
#include <gtest/gtest.h>

#include <cmath>

#include "io/readers.h"

namespace tetstream {
namespace {

using vtkio::chooseTimeStep;
const std::vector<double> kTimes = {0.0, 0.5, 1.0, 1.5};

TEST(TimeSteps, DefaultIsTheLastWithANote) {
  ReadReport report;
  size_t index = 99;
  ASSERT_TRUE(chooseTimeStep(kTimes, {}, "run.exo", report, index));
  EXPECT_EQ(index, 3u);
  EXPECT_EQ(report.stepRead, 3u);
  ASSERT_EQ(report.steps.size(), 4u);
  EXPECT_EQ(report.steps[2].index, 2u);
  EXPECT_EQ(report.steps[2].time, 1.0);
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_NE(report.notes[0].find("4 time steps"), std::string::npos) << report.notes[0];
  EXPECT_NE(report.notes[0].find("--step"), std::string::npos) << report.notes[0];
}

TEST(TimeSteps, ByIndexAndByNearestTime) {
  ReadReport report;
  size_t index = 0;
  ReadOptions byStep;
  byStep.step = 1;
  ASSERT_TRUE(chooseTimeStep(kTimes, byStep, "run.exo", report, index));
  EXPECT_EQ(index, 1u);
  EXPECT_TRUE(report.notes.empty());

  ReadOptions exact;
  exact.time = 1.0;
  ASSERT_TRUE(chooseTimeStep(kTimes, exact, "run.exo", report, index));
  EXPECT_EQ(index, 2u);
  EXPECT_TRUE(report.notes.empty());

  ReadOptions near;
  near.time = 1.3;
  ASSERT_TRUE(chooseTimeStep(kTimes, near, "run.exo", report, index));
  EXPECT_EQ(index, 3u);
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_NE(report.notes[0].find("nearest, step 3"), std::string::npos) << report.notes[0];
}

TEST(TimeSteps, RefusesWhatDoesNotExist) {
  ReadReport report;
  size_t index = 0;
  ReadOptions past;
  past.step = 4;
  Result r = chooseTimeStep(kTimes, past, "run.exo", report, index);
  EXPECT_EQ(r.status, Status::BadArgument);
  EXPECT_NE(r.message.find("steps 0 .. 3"), std::string::npos) << r.message;

  ReadOptions nan;
  nan.time = std::nan("");
  EXPECT_EQ(chooseTimeStep(kTimes, nan, "run.exo", report, index).status, Status::BadArgument);

  ReadOptions both;
  both.step = 0;
  both.time = 0.0;
  EXPECT_EQ(chooseTimeStep(kTimes, both, "run.exo", report, index).status, Status::BadArgument);

  // One state: no step list, and asking for a step is an error rather than silently ignored.
  ReadReport single;
  ASSERT_TRUE(chooseTimeStep({}, {}, "mesh.cgns", single, index));
  EXPECT_EQ(index, 0u);
  EXPECT_TRUE(single.steps.empty());
  ReadOptions first;
  first.step = 0;
  EXPECT_EQ(chooseTimeStep({}, first, "mesh.cgns", single, index).status, Status::BadArgument);
}

}  // namespace
}  // namespace tetstream
