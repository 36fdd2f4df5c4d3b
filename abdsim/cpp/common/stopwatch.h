// Accumulating wall-clock timer for the step profile (StepDiagnostics' time_* fields): adds
// the seconds its scope took to a counter. Costs two steady_clock reads (tens of ns).
#pragma once
#include <chrono>
#include <utility>

namespace abd {

class ScopedStopwatch {
 public:
  explicit ScopedStopwatch(double& seconds)
      : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStopwatch() {
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  ScopedStopwatch(const ScopedStopwatch&) = delete;
  ScopedStopwatch& operator=(const ScopedStopwatch&) = delete;

 private:
  double& seconds_;
  std::chrono::steady_clock::time_point start_;
};

// Seconds since construction or the last split(); for timing consecutive sections.
class Lap {
 public:
  double split() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// f(), its duration added to `seconds`.
template <class F>
auto timed(double& seconds, F&& f) {
  ScopedStopwatch watch(seconds);
  return std::forward<F>(f)();
}

}  // namespace abd
