#include "apps/ibr/bench_gl.h"

#include <fmt/format.h>

#include "render/passes/pass.h"

namespace apps {

std::unique_ptr<BenchGl> StartBenchGl(const std::string& where, int size) {
  auto gl = std::make_unique<BenchGl>();
  gl->context = render::HeadlessContext::Create();
  if (size != 0) render::CheckFrameSize(where, "--size", size, size);
  fmt::print("{} | {}\n", gl->context->info().renderer, gl->context->info().version);
  return gl;
}

}  // namespace apps
