// The GL every `ibr bench` command measures with.
#pragma once

#include <memory>
#include <string>

#include "render/gl/context.h"
#include "render/gl/shader_program.h"

namespace apps {

// A headless context, whose renderer and version are printed first (every
// figure names the GL it came from), and a program cache (declared after
// the context: destroyed before it).
struct BenchGl {
  std::unique_ptr<render::HeadlessContext> context;
  render::ProgramCache programs;
};

// Creates it, prints the renderer line and checks `--size` (`size` pixels a
// side; 0: the bench has no such flag) against the context's limits.
std::unique_ptr<BenchGl> StartBenchGl(const std::string& where, int size);

}  // namespace apps
