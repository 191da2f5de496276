// A tiny fork-join pool for many short rounds of independent tasks. The simplifier evaluates a
// handful of vertices per round, hundreds of thousands of rounds per mesh, so starting a round
// must cost far less than a microsecond: the caller works too, and helpers spin between rounds
// (yielding after a while, so an idle pool does not starve other processes).
//
// Helpers are optional for a round: the caller claims tasks itself and only waits for those a
// helper has already claimed. On a busy machine a descheduled helper then costs nothing; an
// earlier design that waited for every helper to check in was 5× slower when another process
// shared the cores.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <type_traits>
#include <vector>

namespace tetstream {

class WorkPool {
 public:
  explicit WorkPool(unsigned helpers) {
    for (unsigned h = 0; h < helpers; ++h) threads_.emplace_back([this] { helperLoop(); });
  }
  ~WorkPool() {
    stop_.store(true, std::memory_order_relaxed);
    for (std::thread& t : threads_) t.join();
  }
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  // Runs task(k) once for every k in [0, n), on the caller and the helpers; returns when all
  // are done. Tasks must not depend on which thread runs them. n < 2^20.
  template <class F>
  void run(uint32_t n, F&& task) {
    if (threads_.empty() || n <= 1) {
      for (uint32_t k = 0; k < n; ++k) task(k);
      return;
    }
    ctx_ = &task;
    call_ = [](void* ctx, uint32_t k) { (*static_cast<std::remove_reference_t<F>*>(ctx))(k); };
    done_.store(0, std::memory_order_relaxed);
    state_.store(uint64_t(n) << kCountShift, std::memory_order_release);
    uint32_t mine = 0;
    for (uint32_t k; (k = claim()) != kNone;) {
      call_(ctx_, k);
      ++mine;
    }
    for (unsigned spins = 0; done_.load(std::memory_order_acquire) + mine != n;)
      if (++spins > 4096) std::this_thread::yield();
  }

 private:
  // state_ = task count n (20 bits) | next unclaimed task (20 bits): one fetch_add claims a task
  // and tells, from the same value, whether it is a task of the round now running. A claim that
  // lands in a later round than the thread first looked at is a valid task of that round.
  static constexpr int kCountShift = 20;
  static constexpr uint64_t kField = (1u << 20) - 1;
  static constexpr uint32_t kNone = ~0u;

  uint32_t claim(uint64_t s) {
    if ((s & kField) >= (s >> kCountShift & kField)) return kNone;  // nothing left to take
    s = state_.fetch_add(1, std::memory_order_acq_rel);
    uint32_t k = uint32_t(s & kField);
    return k < (s >> kCountShift & kField) ? k : kNone;
  }
  uint32_t claim() { return claim(state_.load(std::memory_order_acquire)); }

  void helperLoop() {
    uint64_t last = 0;
    for (unsigned spins = 0; !stop_.load(std::memory_order_relaxed);) {
      const uint64_t s = state_.load(std::memory_order_acquire);
      if (s != last) spins = 0;  // rounds are still coming: stay awake for the next one
      last = s;
      uint32_t k = claim(s);
      if (k == kNone) {
        if (++spins > 4096) std::this_thread::yield();
        continue;
      }
      call_(ctx_, k);  // ctx_ stays put until done_ says this task has finished
      done_.fetch_add(1, std::memory_order_release);
    }
  }

  std::vector<std::thread> threads_;
  alignas(64) std::atomic<uint64_t> state_{0};  // own cache lines: the helper spins on state_
  alignas(64) std::atomic<uint32_t> done_{0};
  std::atomic<bool> stop_{false};
  void* ctx_ = nullptr;
  void (*call_)(void*, uint32_t) = nullptr;
};

}  // namespace tetstream
