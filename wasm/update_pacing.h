// When the refinement worker sends the page what changed (web/worker.js, docs/js-api.md). While
// it refines, at most every kIntervalMs: the page cannot show more (it draws at the display's
// rate, a software renderer a refining level every 200 ms), and each update costs the worker a
// geometry delta, its figures as JSON and a message, and the page their reading; the changes of
// the slices in between go in one delta. At once when the refinement stops (the last changes
// are never held back), when a command from the page has been applied since the last update (the
// page waits for it to call the view current) and when the fetch plan changed (the page's loader
// follows it). GL- and clock-free: the caller passes the time, so the rule is unit-tested.
#pragma once
#include <cstdint>

namespace tetstream::viewer {

class UpdatePacing {
 public:
  static constexpr double kIntervalMs = 33;

  void commandApplied() { command_ = true; }
  // After a slice of work that ended at nowMs: whether an update goes now. `more`: work is left.
  bool due(double nowMs, bool more, uint32_t planVersion) const {
    return !more || command_ || planVersion != planVersion_ || nowMs - lastMs_ >= kIntervalMs;
  }
  // An update went at nowMs with this plan.
  void sent(double nowMs, uint32_t planVersion) {
    lastMs_ = nowMs;
    planVersion_ = planVersion;
    command_ = false;
  }

 private:
  double lastMs_ = -1e300;
  uint32_t planVersion_ = ~0u;
  bool command_ = false;
};

}  // namespace tetstream::viewer
