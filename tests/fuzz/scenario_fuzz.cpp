// Fuzz harness: scenario JSON text -> bounded parse, schema validation, defaults, stage options.
// A terrapolis::Error is the expected refusal; anything else (another exception, a signal, a
// sanitizer report) is a defect.
// SPDX-License-Identifier: MIT
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "pipeline/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto scenario = terrapolis::pipeline::scenario_from_text(text, "fuzz.json");
    (void)scenario.resolved.dump();  // run.json serialises it
  } catch (const terrapolis::Error&) {
  }
  return 0;
}
