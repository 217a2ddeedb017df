#include "tests/support/gl_test.h"

#include <cstdlib>
#include <memory>

#include "core/image_io.h"

namespace test_support {

namespace {
struct Shared {
  std::unique_ptr<render::HeadlessContext> context;
  std::unique_ptr<render::ProgramCache> programs;
  std::string failure;
  bool tried = false;
};
Shared& GetShared() {
  static Shared shared;
  return shared;
}
}  // namespace

render::HeadlessContext* SharedContext(std::string* reason) {
  Shared& s = GetShared();
  if (!s.tried) {
    s.tried = true;
    try {
      s.context = render::HeadlessContext::Create();
      s.programs = std::make_unique<render::ProgramCache>();
    } catch (const std::exception& e) {
      s.failure = e.what();
    }
  }
  if (reason) *reason = s.failure;
  return s.context.get();
}

std::filesystem::path TestOutputDir() {
  const char* root = std::getenv("IBR_TEST_OUTPUT");
  std::filesystem::path dir = root ? root : "test-output";
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  if (info) dir /= std::string(info->test_suite_name()) + "." + info->name();
  // Fresh for each test: the first call in a test empties what an earlier run
  // left. Outside a test (SetUpTestSuite) this is the shared root, which other
  // test processes are writing into: never empty it.
  static std::string last;
  if (info && last != dir.string()) {
    last = dir.string();
    std::filesystem::remove_all(dir);
  }
  std::filesystem::create_directories(dir);
  return dir;
}

void WriteDebugImage(const std::string& name, const core::Image8& image) {
  const auto path = TestOutputDir() / name;
  core::WriteImage(path, image);
  std::printf("wrote %s\n", path.c_str());
}

void WriteDebugImage(const std::string& name, const core::ImageF& image) {
  const auto path = TestOutputDir() / name;
  core::WriteImage(path, image);
  std::printf("wrote %s\n", path.c_str());
}

std::filesystem::path SharedData(const std::string& relative) {
  const char* root = std::getenv("IBR_SHARED_DATA");
  if (!root || !*root) return {};
  const auto path = std::filesystem::path(root) / relative;
  return std::filesystem::exists(path) ? path : std::filesystem::path();
}

void GlTest::SetUp() {
  std::string reason;
  if (!SharedContext(&reason)) {
    const char* require = std::getenv("IBR_REQUIRE_GL");
    if (require && std::string(require) == "1") {
      FAIL() << "no GL context and IBR_REQUIRE_GL=1: " << reason;
    } else {
      GTEST_SKIP() << "no OpenGL context can be made here: " << reason;
    }
  }
  render::DrainGlErrors();
}

void GlTest::TearDown() {
  if (SharedContext()) {
    EXPECT_NO_GL_ERROR();
  }
}

render::ProgramCache& GlTest::programs() { return *GetShared().programs; }

}  // namespace test_support
