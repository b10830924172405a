#pragma once

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace norm2tex {

/// Runs the jobs 0 .. count - 1 of one call on a fixed set of threads: the caller's and
/// `threads - 1` workers that live as long as this object and wait on a condition variable
/// between calls (no thread is started per call, none spins).
///
/// Why not OpenCV's or OpenMP's pool: the jobs here are whole physics steps and sensor renders
/// of about a millisecond, each with its own thread_local scratch; workers kept for the
/// object's life keep that scratch warm, and the caller (Python, with the GIL released) waits
/// for exactly its own jobs.
class ParallelFor {
 public:
  /// `threads` >= 1 (the caller counts as one); 0: std::thread::hardware_concurrency().
  explicit ParallelFor(int threads = 0);
  ~ParallelFor();
  ParallelFor(const ParallelFor&) = delete;
  ParallelFor& operator=(const ParallelFor&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls job(i) once for every i in [0, count), in any order and on any of the threads, and
  /// returns when all have returned. The first exception a job throws is rethrown here (the
  /// other jobs still run). Not reentrant: one call at a time.
  void run(int count, const std::function<void(int)>& job);

 private:
  void work();
  void runJobs(std::unique_lock<std::mutex>& lock);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(int)>* job_ = nullptr;
  int count_ = 0;
  int next_ = 0;
  int finished_ = 0;
  std::uint64_t generation_ = 0;
  bool stopping_ = false;
  std::exception_ptr error_;
};

}  // namespace norm2tex
