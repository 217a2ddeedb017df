// A bench as a declarative sweep: a list of configurations, a measure that
// turns one configuration into table rows, and the loop between them. A bench
// builds its configuration list (Product of its option lists), writes one
// short measure function per kind of row, and assembles tables from them, so
// no function in bench/ grows past a screen (tests/docs/function_length.py).
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <cstdio>
#include <functional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace bench {

namespace sweep_internal {
template <size_t I, class Tuple, class Lists>
void ProductInto(std::vector<Tuple>& out, Tuple& current, const Lists& lists) {
  if constexpr (I == std::tuple_size_v<Tuple>) {
    out.push_back(current);
  } else {
    for (const auto& value : *std::get<I>(lists)) {
      std::get<I>(current) = value;
      ProductInto<I + 1>(out, current, lists);
    }
  }
}
}  // namespace sweep_internal

// Every combination of the values of `lists`, the first list varying slowest
// (the nesting order of the loops it replaces).
template <class... T>
std::vector<std::tuple<T...>> Product(const std::vector<T>&... lists) {
  std::vector<std::tuple<T...>> out;
  std::tuple<T...> current{};
  sweep_internal::ProductInto<0>(out, current, std::make_tuple(&lists...));
  return out;
}

struct SweepOptions {
  // Rounds over the whole configuration list: round r measures every
  // configuration before round r + 1 starts, so a slow spell of a shared
  // machine spreads over all configurations instead of hitting one.
  int rounds = 1;
  // "bench NAME" for the progress lines on stderr; empty: silent (a bench
  // that prints its own progress keeps its lines).
  std::string progress;
};

// Runs `measure(config, round)` for every configuration, `rounds` times in
// interleaved order. `label(config)` names a configuration in the progress
// line (`progress: round r/R, i/N: label`).
template <class Config>
void Sweep(const std::vector<Config>& configs, const SweepOptions& options,
           const std::function<void(const Config&, int round)>& measure,
           const std::function<std::string(const Config&)>& label = {}) {
  for (int round = 0; round < options.rounds; ++round) {
    for (size_t i = 0; i < configs.size(); ++i) {
      if (!options.progress.empty()) {
        fmt::print(stderr, "{}: round {}/{}, {}/{}{}\n", options.progress, round + 1,
                   options.rounds, i + 1, configs.size(), label ? ": " + label(configs[i]) : "");
      }
      measure(configs[i], round);
    }
  }
}

}  // namespace bench
