// GL test support: one headless context per test process, shared by all GL
// tests; a fixture that ends every test with ExpectNoGlError(); helpers to
// write actual/diff images into the build tree when a comparison fails.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/image.h"
#include "render/gl/context.h"
#include "render/gl/gl_debug.h"
#include "render/gl/shader_program.h"

namespace test_support {

// The shared context, created on first use; nullptr (with `reason` set) when
// none can be made.
render::HeadlessContext* SharedContext(std::string* reason = nullptr);

// Where tests write files: $IBR_TEST_OUTPUT/<suite.test>/, created, and
// emptied on its first use in each test (outside a test: the root, kept).
std::filesystem::path TestOutputDir();

// Writes `image` as PNG/EXR (by extension) under TestOutputDir().
void WriteDebugImage(const std::string& name, const core::Image8& image);
void WriteDebugImage(const std::string& name, const core::ImageF& image);

// Path of a file in ../shared/data (from $IBR_SHARED_DATA); empty when the
// data folder is absent.
std::filesystem::path SharedData(const std::string& relative);

class GlTest : public ::testing::Test {
 protected:
  // Skips with the reason when no context can be made, unless the
  // environment sets IBR_REQUIRE_GL=1 (CI does), where it fails instead.
  void SetUp() override;
  void TearDown() override;
  render::ProgramCache& programs();
};

}  // namespace test_support

#define EXPECT_NO_GL_ERROR() EXPECT_EQ(::render::DrainGlErrors(), "")
