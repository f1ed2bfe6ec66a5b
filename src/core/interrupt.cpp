// SPDX-License-Identifier: MIT
#include "core/interrupt.hpp"

#include <atomic>
#include <csignal>

#include "core/error.hpp"

namespace terrapolis {
namespace {

std::atomic<int> caught{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler may only touch a lock-free atomic");

extern "C" void on_signal(int signal) { caught.store(signal, std::memory_order_relaxed); }

}  // namespace

void catch_interrupts() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // the second signal takes its default action: a user can still kill
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int interrupt_signal() noexcept { return caught.load(std::memory_order_relaxed); }

void stop_if_interrupted() {
  if (const int s = interrupt_signal()) throw Error(ErrorKind::cancelled, s == SIGINT ? "interrupted (SIGINT)" : "interrupted (SIGTERM)");
}

}  // namespace terrapolis
