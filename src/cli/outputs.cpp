// Writing a command's outputs.
// SPDX-License-Identifier: MIT
#include <tbb/parallel_for.h>

#include "cli/command.hpp"

namespace terrapolis::cli {

void write_concurrently(const std::vector<std::function<void()>>& writes) {
  tbb::parallel_for(std::size_t(0), writes.size(), [&](std::size_t i) { writes[i](); });
}

}  // namespace terrapolis::cli
