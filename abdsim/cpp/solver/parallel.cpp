#include "solver/parallel.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace abd {
namespace {

// Workers sleep on a condition variable between loops, after polling for a new loop for
// this long (consecutive loops of a time step then start without a wake-up).
constexpr auto kSpinBeforeSleep = std::chrono::microseconds(50);

class WorkerPool {
 public:
  static WorkerPool& instance() {
    // Never destroyed: sleeping workers must not be joined during interpreter shutdown.
    static WorkerPool* pool = new WorkerPool();
    return *pool;
  }

  int hardware_threads() const { return static_cast<int>(workers_.size()) + 1; }

  void run(int n, int chunk, int threads, const std::function<void(int, int, int)>& f) {
    const int chunks = (n + chunk - 1) / chunk;
    std::unique_lock<std::mutex> busy(run_mutex_, std::try_to_lock);
    if (!busy.owns_lock() || threads <= 1 || workers_.empty()) {  // another loop is running
      f(0, n, 0);
      return;
    }
    std::uint32_t gen;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = Job{&f, n, chunk, chunks};
      helpers_.store(0);
      done_.store(0);
      gen = ++generation_;
      cursor_.store(static_cast<std::uint64_t>(gen) << 32);
      max_helpers_ = threads - 1;
      published_.store(gen, std::memory_order_release);
    }
    cv_.notify_all();
    work(job_, gen, 0);
    // Wait only for chunks that were claimed: workers that never woke up owe nothing.
    while (done_.load(std::memory_order_acquire) < chunks) std::this_thread::yield();
  }

 private:
  struct Job {
    const std::function<void(int, int, int)>* f = nullptr;
    int n = 0;
    int chunk = 1;
    int chunks = 0;
  };

  WorkerPool() {
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned i = 1; i < hw; ++i) workers_.emplace_back([this] { worker_loop(); });
    for (auto& w : workers_) w.detach();
  }

  // Claims and runs chunks of generation `gen` until none is left.
  void work(const Job& job, std::uint32_t gen, int slot) {
    while (true) {
      std::uint64_t cur = cursor_.load();
      if ((cur >> 32) != gen) return;  // a newer loop has started: this one is over
      const int index = static_cast<int>(cur & 0xffffffffu);
      if (index >= job.chunks) return;
      if (!cursor_.compare_exchange_weak(cur, cur + 1)) continue;
      const int begin = index * job.chunk;
      (*job.f)(begin, std::min(job.n, begin + job.chunk), slot);
      done_.fetch_add(1, std::memory_order_release);
    }
  }

  void worker_loop() {
    std::uint32_t seen = 0;
    while (true) {
      const auto spin_end = std::chrono::steady_clock::now() + kSpinBeforeSleep;
      while (published_.load(std::memory_order_acquire) == seen &&
             std::chrono::steady_clock::now() < spin_end) {
        std::this_thread::yield();
      }
      Job job;
      int slot;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [&] { return generation_ != seen; });
        seen = generation_;
        job = job_;
        slot = helpers_.fetch_add(1) + 1;
        if (slot > max_helpers_) continue;  // the loop asked for fewer threads
      }
      work(job, seen, slot);
    }
  }

  std::vector<std::thread> workers_;
  std::mutex run_mutex_;  // one loop at a time; a concurrent caller runs serially
  std::mutex mutex_;      // guards job_, generation_, max_helpers_
  std::condition_variable cv_;
  Job job_;
  std::uint32_t generation_ = 0;
  int max_helpers_ = 0;
  std::atomic<std::uint32_t> published_{0};  // generation_, readable without the lock
  std::atomic<std::uint64_t> cursor_{0};     // generation << 32 | next chunk
  std::atomic<int> done_{0};                 // chunks finished in the current loop
  std::atomic<int> helpers_{0};              // workers that joined the current loop
};

}  // namespace

int resolve_threads(int requested) {
  return requested > 0 ? requested : WorkerPool::instance().hardware_threads();
}

void parallel_chunks(int n, int chunk, int threads,
                     const std::function<void(int, int, int)>& f) {
  if (n <= 0) return;
  WorkerPool::instance().run(n, std::max(chunk, 1), threads, f);
}

}  // namespace abd
