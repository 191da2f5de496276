// A tiny fork-join pool for many short rounds of independent tasks. The simplifier evaluates a
// handful of vertices per round, hundreds of thousands of rounds per mesh, so starting a round
// must cost far less than a microsecond: the caller works too, and helpers spin between rounds
// (yielding after a while, so an idle pool does not starve other processes).
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
    round_.fetch_add(1, std::memory_order_release);
    for (std::thread& t : threads_) t.join();
  }
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  // Runs task(k) once for every k in [0, n), on the caller and the helpers; returns when all
  // are done. Tasks must not depend on which thread runs them.
  template <class F>
  void run(uint32_t n, F&& task) {
    if (threads_.empty() || n <= 1) {
      for (uint32_t k = 0; k < n; ++k) task(k);
      return;
    }
    ctx_ = &task;
    call_ = [](void* ctx, uint32_t k) { (*static_cast<std::remove_reference_t<F>*>(ctx))(k); };
    n_ = n;
    next_.store(0, std::memory_order_relaxed);
    busy_.store(uint32_t(threads_.size()), std::memory_order_relaxed);
    round_.fetch_add(1, std::memory_order_release);  // publishes the fields above
    work();
    for (unsigned spins = 0; busy_.load(std::memory_order_acquire) != 0;)
      if (++spins > 4096) std::this_thread::yield();
  }

 private:
  void work() {
    for (uint32_t k; (k = next_.fetch_add(1, std::memory_order_relaxed)) < n_;) call_(ctx_, k);
  }

  void helperLoop() {
    uint64_t seen = 0;  // not a load: a thread that starts late must still see the first round
    for (;;) {
      uint64_t r;
      for (unsigned spins = 0; (r = round_.load(std::memory_order_acquire)) == seen;)
        if (++spins > 4096) std::this_thread::yield();
      seen = r;
      if (stop_.load(std::memory_order_relaxed)) return;
      work();
      busy_.fetch_sub(1, std::memory_order_release);  // this round's tasks are finished
    }
  }

  std::vector<std::thread> threads_;
  std::atomic<uint64_t> round_{0};
  std::atomic<uint32_t> next_{0}, busy_{0};
  std::atomic<bool> stop_{false};
  void* ctx_ = nullptr;
  void (*call_)(void*, uint32_t) = nullptr;
  uint32_t n_ = 0;
};

}  // namespace tetstream
