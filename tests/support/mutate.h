// Small random edits of a text or binary file for the readers' "arbitrary
// bytes" tests (STYLE.md): 1..4 edits, each a random byte, a deletion of
// 1..8 bytes, or an inserted digit, space, minus or newline (what counts and
// numbers are made of). Deterministic for a seeded `rng`.
#pragma once

#include <random>
#include <string>

namespace test_support {

inline void MutateBytes(std::string& s, std::mt19937& rng) {
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits && !s.empty(); ++e) {
    const size_t at = rng() % s.size();
    switch (rng() % 3) {
      case 0:
        s[at] = static_cast<char>(rng());
        break;
      case 1:
        s.erase(at, 1 + rng() % 8);
        break;
      default:
        s.insert(at, 1, "0123456789 -\n"[rng() % 13]);
    }
  }
}

}  // namespace test_support
