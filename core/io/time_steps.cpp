#include <cmath>
#include <cstdio>

#include "io/readers.h"

namespace tetstream::vtkio {
namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Result chooseTimeStep(std::span<const double> times, const ReadOptions& options, const std::string& label,
                      ReadReport& report, size_t& index) {
  index = 0;
  report.steps.clear();
  if (options.step && options.time) return fail(Status::BadArgument, label + ": give --step or --time, not both");
  if (times.empty()) {
    if (options.step || options.time)
      return fail(Status::BadArgument, label + ": holds no time steps, so --step and --time do not apply");
    return Result::success();
  }
  for (size_t i = 0; i < times.size(); ++i) report.steps.push_back({uint64_t(i), times[i]});
  const std::string span =
      std::to_string(times.size()) + " time steps (t = " + number(times.front()) + " .. " + number(times.back()) + ")";
  if (options.step) {
    if (*options.step >= times.size())
      return fail(Status::BadArgument, label + ": --step " + std::to_string(*options.step) +
                                           " does not exist; it has " + span + ", steps 0 .. " +
                                           std::to_string(times.size() - 1));
    index = size_t(*options.step);
  } else if (options.time) {
    if (!std::isfinite(*options.time)) return fail(Status::BadArgument, label + ": --time must be a finite number");
    // The nearest step: times written as text or in float32 rarely equal the value typed.
    for (size_t i = 1; i < times.size(); ++i)
      if (std::fabs(times[i] - *options.time) < std::fabs(times[index] - *options.time)) index = i;
    if (times[index] != *options.time)
      report.notes.push_back("no step at t = " + number(*options.time) + "; read the nearest, step " +
                             std::to_string(index) + " (t = " + number(times[index]) + ")");
  } else {
    index = times.size() - 1;
    if (times.size() > 1)
      report.notes.push_back(label + " has " + span + "; read the last, step " + std::to_string(index) +
                             " (choose another with --step K or --time T)");
  }
  report.stepRead = index;
  return Result::success();
}

std::string stepText(const ReadReport& report) {
  if (report.steps.empty()) return "";
  return ", step " + std::to_string(report.stepRead) + " of " + std::to_string(report.steps.size()) +
         " (t = " + number(report.steps[report.stepRead].time) + ")";
}

}  // namespace tetstream::vtkio
