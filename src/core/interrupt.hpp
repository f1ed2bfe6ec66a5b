// SIGINT and SIGTERM: a flag the work polls at its progress ticks, so an interrupt stops cleanly.
// SPDX-License-Identifier: MIT
#pragma once

namespace terrapolis {

/// Catches SIGINT and SIGTERM. The first one only sets a flag (async-signal-safe); the work stops
/// at its next progress tick and removes its temporary outputs. A second one kills at once.
void catch_interrupts();

/// The signal caught (SIGINT, SIGTERM), or 0.
int interrupt_signal() noexcept;

/// Throws Error(cancelled) naming the signal when one was caught.
void stop_if_interrupted();

}  // namespace terrapolis
