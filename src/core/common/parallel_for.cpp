#include "norm2tex/common/parallel_for.hpp"

#include <algorithm>

namespace norm2tex {

ParallelFor::ParallelFor(int threads) {
  if (threads <= 0) threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back(&ParallelFor::work, this);
}

ParallelFor::~ParallelFor() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void ParallelFor::runJobs(std::unique_lock<std::mutex>& lock) {
  // Takes jobs until none are left; the lock is held between jobs, not during one.
  while (next_ < count_) {
    const int i = next_++;
    const std::function<void(int)>& job = *job_;
    lock.unlock();
    std::exception_ptr error;
    try {
      job(i);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error && !error_) error_ = error;
    if (++finished_ == count_) done_.notify_all();
  }
}

void ParallelFor::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  std::uint64_t seen = generation_;
  while (true) {
    wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
    if (stopping_) return;
    seen = generation_;
    runJobs(lock);
  }
}

void ParallelFor::run(int count, const std::function<void(int)>& job) {
  if (count <= 0) return;
  std::unique_lock<std::mutex> lock(mutex_);
  job_ = &job;
  count_ = count;
  next_ = 0;
  finished_ = 0;
  error_ = nullptr;
  ++generation_;
  if (count > 1) wake_.notify_all();
  runJobs(lock);
  done_.wait(lock, [&] { return finished_ == count_; });
  // A worker woken late finds next_ == count_ and takes nothing: job_ may be dropped now.
  job_ = nullptr;
  count_ = 0;
  next_ = 0;
  const std::exception_ptr error = error_;
  error_ = nullptr;
  lock.unlock();
  if (error) std::rethrow_exception(error);
}

}  // namespace norm2tex
