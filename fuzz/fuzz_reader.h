// Shared body of the libFuzzer targets: a reader meets arbitrary bytes
// through a stream. The only acceptable failure is core::InputError (a clean
// rejection); anything else (another exception, a sanitizer report, a crash)
// is a bug. When the reader accepts the input, its writer must produce bytes
// that the reader accepts again and that write back identically:
// Write(Read(Write(Read(x)))) == Write(Read(x)).
// Readers without a writer: FuzzReaderOnly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "core/error.h"

namespace fuzz {

template <typename Read, typename Write>
int FuzzReader(const uint8_t* data, size_t size, Read read, Write write) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::string first;
  try {
    const auto value = read(in);
    std::ostringstream out;
    write(out, value);
    first = out.str();
  } catch (const core::InputError&) {
    return 0;  // rejected with a message: the expected outcome for most inputs
  }
  std::istringstream again(first);
  std::ostringstream out2;
  try {
    write(out2, read(again));
  } catch (const core::InputError& e) {
    std::fprintf(stderr, "fuzz: the reader rejects what the writer wrote: %s\n", e.what());
    std::abort();
  }
  if (out2.str() != first) {
    std::fprintf(stderr, "fuzz: write(read(write(read(x)))) differs from write(read(x))\n");
    std::abort();
  }
  return 0;
}

// For readers without a writer (Redwood .log, Middlebury _par.txt): only a
// clean rejection or a result.
template <typename Read>
int FuzzReaderOnly(const uint8_t* data, size_t size, Read read) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    read(in);
  } catch (const core::InputError&) {
  }
  return 0;
}

}  // namespace fuzz
