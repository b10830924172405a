// norm2tex_wake_bench: this machine's floor under a real-time frame, without ROS or rendering.
//   norm2tex_wake_bench [FRAMES]
// A frame of the simulated gripper is a chain of thread wake-ups: contact_sim's clock thread
// sleeps to the frame's tick, wakes both renderers (which must run on different CPUs, in
// parallel), and each renderer wakes roscpp's poll thread, which sends the image. At FRAMES
// ticks of 60 Hz this measures, as p50 / p90 / p99 / max:
//   - how late a thread sleeping to an absolute time (clock_nanosleep) wakes;
//   - a hand-over through a pipe to a thread in epoll_wait (roscpp's poll-set signal), with
//     both threads pinned to the same CPU, and to different CPUs;
//   - what a sleep costs the work after it: a pass over 4 MiB (the order of a render's working
//     set) and a register-only arithmetic loop, each timed back to back and at every tick after
//     sleeping to it. Where the memory pass is slower after the sleep and the arithmetic is not,
//     the caches were emptied while the thread slept (tactile_renderer's ~rehearse_ms).
// On bare metal all of these are tens of microseconds. On a virtual machine a wake-up of an
// idle virtual CPU waits for the host to run it: that is the tail a frame's latency inherits.
#include <sched.h>
#include <sys/epoll.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "cli_arguments.hpp"

namespace {

constexpr std::int64_t kPeriodNs = 16'666'667;  // 60 Hz, the sensors' frame rate

std::int64_t nowNs() {
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void sleepUntil(std::int64_t ns) {
  const timespec when{static_cast<time_t>(ns / 1'000'000'000),
                      static_cast<long>(ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &when, nullptr) == EINTR) {
  }
}

bool pinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return sched_setaffinity(0, sizeof(set), &set) == 0;
}

void report(const char* what, std::vector<double> ms) {
  if (ms.empty()) return;
  std::sort(ms.begin(), ms.end());
  const auto at = [&](double q) {
    return ms[std::min(ms.size() - 1, static_cast<std::size_t>(q * (ms.size() - 1) + 0.5))];
  };
  std::printf("  %-44s p50 %.3f  p90 %.3f  p99 %.3f  max %.3f ms\n", what, at(0.5), at(0.9),
              at(0.99), at(1.0));
}

/// Timer lateness: one thread sleeping to each 60 Hz tick.
std::vector<double> timerLateness(int frames) {
  std::vector<double> late;
  std::int64_t next = nowNs() + kPeriodNs;
  for (int i = 0; i < frames; ++i, next += kPeriodNs) {
    sleepUntil(next);
    late.push_back(1e-6 * static_cast<double>(nowNs() - next));
  }
  return late;
}

/// A ticking thread on `sender_cpu` writes a byte to a pipe at every tick; a thread on
/// `receiver_cpu` waits in epoll_wait, as roscpp's poll thread does. Returns the hand-over times,
/// or nothing when a CPU cannot be pinned.
std::vector<double> pipeHandOver(int frames, int sender_cpu, int receiver_cpu) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const int poll_fd = epoll_create1(0);
  epoll_event event{};
  event.events = EPOLLIN;
  epoll_ctl(poll_fd, EPOLL_CTL_ADD, fds[0], &event);
  std::atomic<std::int64_t> sent_at{0};
  std::atomic<bool> pinned{true};
  std::vector<double> hand_over;
  std::thread receiver([&] {
    if (!pinTo(receiver_cpu)) pinned = false;
    for (;;) {
      epoll_event ready;
      if (epoll_wait(poll_fd, &ready, 1, 1000) <= 0) continue;
      const std::int64_t now = nowNs();
      char byte = 0;
      if (read(fds[0], &byte, 1) != 1 || byte == 0) return;
      hand_over.push_back(1e-6 * static_cast<double>(now - sent_at.load()));
    }
  });
  std::thread sender([&] {
    if (!pinTo(sender_cpu)) pinned = false;
    std::int64_t next = nowNs() + kPeriodNs;
    for (int i = 0; i < frames && pinned; ++i, next += kPeriodNs) {
      sleepUntil(next);
      sent_at = nowNs();
      const char byte = 1;
      if (write(fds[1], &byte, 1) != 1) break;
    }
    const char stop = 0;
    (void)!write(fds[1], &stop, 1);
  });
  sender.join();
  receiver.join();
  close(fds[0]);
  close(fds[1]);
  close(poll_fd);
  if (!pinned) return {};
  return hand_over;
}

/// Seconds of arithmetic on registers only (no memory traffic): a CPU that runs slower after
/// a sleep shows here.
double arithmeticMs() {
  const std::int64_t start = nowNs();
  double a = 1.0, b = 0.5;
  for (int i = 0; i < 200'000; ++i) {
    a = a * 1.0000001 + 1e-9;
    b = b * 0.9999999 + 1e-9;
  }
  volatile double sink = a + b;
  (void)sink;
  return 1e-6 * static_cast<double>(nowNs() - start);
}

/// A read-modify-write of every cache line of `memory`.
double memoryPassMs(std::vector<unsigned char>& memory) {
  const std::int64_t start = nowNs();
  for (std::size_t i = 0; i < memory.size(); i += 64) ++memory[i];
  return 1e-6 * static_cast<double>(nowNs() - start);
}

/// The arithmetic loop and the 4 MiB pass, `frames` times back to back (`paced` false) or at
/// each 60 Hz tick after sleeping to it, on CPU 0.
void afterSleep(int frames, bool paced, std::vector<double>& arithmetic,
                std::vector<double>& memory_pass) {
  std::thread worker([&] {
    pinTo(0);
    std::vector<unsigned char> memory(4u << 20, 1);
    memoryPassMs(memory);  // faulted in before timing
    std::int64_t next = nowNs() + kPeriodNs;
    for (int i = 0; i < frames; ++i, next += kPeriodNs) {
      if (paced) sleepUntil(next);
      arithmetic.push_back(arithmeticMs());
      memory_pass.push_back(memoryPassMs(memory));
    }
  });
  worker.join();
}

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_wake_bench", "norm2tex_wake_bench [FRAMES]",
      "Measures this machine's floor under a real-time frame, without ROS or rendering, at\n"
      "FRAMES ticks of 60 Hz (at least 10, default 1200), as p50 / p90 / p99 / max: how late a\n"
      "thread sleeping to a tick wakes, a hand-over through a pipe to a thread in epoll_wait on\n"
      "the same CPU and on another, and what a sleep costs the work after it (a 4 MiB memory\n"
      "pass and an arithmetic loop, back to back and right after sleeping to a tick).");
  program.positional("FRAMES", 1, norm2tex::cli::po::value<int>());
  return program;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  const int frames = norm2tex::cli::valueOr(program.parse(argc, argv), "FRAMES", 1200);
  if (frames < 10) {
    throw norm2tex::cli::UsageError("FRAMES must be at least 10, got " + std::to_string(frames));
  }
  const unsigned cpus = std::thread::hardware_concurrency();
  std::printf("wake-ups at 60 Hz, %d frames each, %u CPUs:\n", frames, cpus);
  report("sleep to a tick (clock_nanosleep): lateness", timerLateness(frames));
  report("pipe -> epoll_wait hand-over, same CPU", pipeHandOver(frames, 0, 0));
  if (cpus > 1) report("pipe -> epoll_wait hand-over, other CPU", pipeHandOver(frames, 0, 1));
  std::vector<double> arithmetic_loop, memory_loop, arithmetic_paced, memory_paced;
  afterSleep(frames, false, arithmetic_loop, memory_loop);
  afterSleep(frames, true, arithmetic_paced, memory_paced);
  report("arithmetic, back to back", arithmetic_loop);
  report("arithmetic, right after sleeping to a tick", arithmetic_paced);
  report("4 MiB memory pass, back to back", memory_loop);
  report("4 MiB memory pass, after sleeping to a tick", memory_paced);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
