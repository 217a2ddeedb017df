// `ibr verify` as a library (verify/verify.h): a short run on this driver is
// clean against both references; an injected off-by-one in the mirror is
// reported as real errors; a simulated driver whose division is 2 ULP off
// (allowed by GLSL) is reported as permitted mismatches, not errors; the
// hard-case sweeps give finite, consistent pixels. The full runs (1000
// cases, 1000 hard cases per technique) are `ibr verify` and the `hard` label.
#include "verify/verify.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/error.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

class VerifyTest : public test_support::GlTest {};

TEST_F(VerifyTest, ShortRunIsCleanAgainstBothReferences) {
  VerifyOptions o;
  o.cases = 24;
  o.seed = 2001;
  o.independent = true;
  o.out = test_support::TestOutputDir();
  const VerifyReport r = RunVerify(programs(), o);
  std::printf(
      "verify: %d cases in %.1f s, %lld pixels, %lld mismatched (%lld permitted, %lld real), "
      "independent: %lld agree, band %lld (%lld disagree), %lld real\n",
      r.cases, r.seconds, static_cast<long long>(r.total.pixels),
      static_cast<long long>(r.total.mismatched), static_cast<long long>(r.total.permitted),
      static_cast<long long>(r.total.real_errors),
      static_cast<long long>(r.total.independent.agree),
      static_cast<long long>(r.total.independent.band),
      static_cast<long long>(r.total.independent.band_disagree),
      static_cast<long long>(r.total.independent.real_errors));
  EXPECT_EQ(r.cases, 24);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.total.real_errors, 0);
  EXPECT_EQ(r.total.independent.real_errors, 0);
  EXPECT_GT(r.total.pixels, 24 * 24 * 24);
  EXPECT_GT(r.total.independent.agree, r.total.pixels * 9 / 10);
  EXPECT_GT(r.boundary_cases[0] + r.boundary_cases[1] + r.boundary_cases[2], 0)
      << "boundary cases must occur";
  // Colour of the slice path and the ray path, against the same reference.
  std::printf(
      "  slice colour compared on %lld pixels (%lld outside); ray path: %lld pixels, %lld object, "
      "%lld agree, band %lld (%lld disagree), alternatives %lld (%lld taken), %lld real, colour "
      "on %lld (%lld outside)\n",
      static_cast<long long>(r.total.independent.color_checked),
      static_cast<long long>(r.total.independent.color_errors),
      static_cast<long long>(r.total.ray.pixels), static_cast<long long>(r.total.ray.covered),
      static_cast<long long>(r.total.ray.agree), static_cast<long long>(r.total.ray.band),
      static_cast<long long>(r.total.ray.band_disagree),
      static_cast<long long>(r.total.ray.alternative_pixels),
      static_cast<long long>(r.total.ray.alternative_taken),
      static_cast<long long>(r.total.ray.real_errors),
      static_cast<long long>(r.total.ray.color_checked),
      static_cast<long long>(r.total.ray.color_errors));
  EXPECT_GT(r.total.independent.color_checked, 1000);
  EXPECT_EQ(r.total.independent.color_errors, 0);
  EXPECT_EQ(r.total.ray.pixels, r.total.pixels);
  EXPECT_GT(r.total.ray.covered, 1000);
  EXPECT_EQ(r.total.ray.real_errors, 0);
  EXPECT_GT(r.total.ray.color_checked, 1000);
  EXPECT_NO_GL_ERROR();
}

// Case i of a seed is the same alone (--first-case i --cases 1) as in a run.
TEST_F(VerifyTest, FirstCaseRerunsOneCaseAlone) {
  VerifyOptions o;
  o.cases = 4;
  o.seed = 5;
  std::vector<VerifyCaseResult> run;
  RunVerify(programs(), o, [&](const VerifyCaseResult& r) { run.push_back(r); });
  ASSERT_EQ(run.size(), 4u);
  o.first_case = 3;
  o.cases = 1;
  std::vector<VerifyCaseResult> alone;
  RunVerify(programs(), o, [&](const VerifyCaseResult& r) { alone.push_back(r); });
  ASSERT_EQ(alone.size(), 1u);
  EXPECT_EQ(alone[0].index, 3);
  EXPECT_EQ(alone[0].description, run[3].description);
  EXPECT_EQ(alone[0].pixels, run[3].pixels);
  EXPECT_NO_GL_ERROR();
}

TEST_F(VerifyTest, InjectedOffByOneIsARealError) {
  VerifyOptions o;
  o.cases = 6;
  o.seed = 7;
  o.inject_fault = 1;
  o.out = test_support::TestOutputDir();
  const VerifyReport r = RunVerify(programs(), o);
  EXPECT_FALSE(r.ok());
  EXPECT_GT(r.total.real_errors, 0);
  EXPECT_GT(r.failing_cases, 0);
  EXPECT_NO_GL_ERROR();
}

TEST_F(VerifyTest, DivisionWithinTwoAndAHalfUlpIsPermitted) {
  VerifyOptions o;
  o.cases = 8;
  o.seed = 11;
  o.inject_fault = 2;
  const VerifyReport r = RunVerify(programs(), o);
  EXPECT_GT(r.total.permitted, 0) << "the loose division must change some depths";
  EXPECT_EQ(r.total.real_errors, 0);
  EXPECT_TRUE(r.ok());
  EXPECT_NO_GL_ERROR();
}

TEST_F(VerifyTest, BadOptionsAreRejected) {
  VerifyOptions o;
  o.cases = 0;
  EXPECT_THROW(o.Check(), core::InputError);
  o.cases = 1;
  o.method = "cubes";
  EXPECT_THROW(o.Check(), core::InputError);
  o.method = "ncs";  // a technique of the hard sweeps only
  EXPECT_THROW(o.Check(), core::InputError);
  o.hard = true;
  EXPECT_NO_THROW(o.Check());
  o.first_case = -1;
  EXPECT_THROW(o.Check(), core::InputError);
}

// A few hard cases of every technique (the full sweep: label `hard`).
TEST_F(VerifyTest, HardSweepSmokeIsFiniteAndConsistent) {
  VerifyOptions o;
  o.cases = 24;  // two of every degenerate kind
  o.seed = 3;
  const HardReport r = RunHardSweeps(programs(), o);
  ASSERT_EQ(r.techniques.size(), 7u);
  for (const HardTechniqueResult& t : r.techniques) {
    EXPECT_EQ(t.cases, 24) << t.technique;
    EXPECT_EQ(t.nonfinite, 0) << t.technique;
    EXPECT_EQ(t.inconsistent, 0) << t.technique;
    EXPECT_GT(t.covered, 0) << t.technique << " must draw something";
  }
  EXPECT_NO_GL_ERROR();
}

// >= 1000 random degenerate configurations per technique (ctest -L hard).
TEST_F(VerifyTest, HardSweepFull) {
  if (std::getenv("IBR_HARD") == nullptr) GTEST_SKIP() << "set IBR_HARD=1 (ctest -L hard does)";
  VerifyOptions o;
  o.cases = 1000;
  o.seed = 1;
  const HardReport r = RunHardSweeps(
      programs(), o, [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  for (const HardTechniqueResult& t : r.techniques) {
    std::printf(
        "%-13s %d cases, %lld pixels, %lld covered, %lld NaN/Inf, %lld inconsistent, %.1f s\n",
        t.technique.c_str(), t.cases, static_cast<long long>(t.pixels),
        static_cast<long long>(t.covered), static_cast<long long>(t.nonfinite),
        static_cast<long long>(t.inconsistent), t.seconds);
    for (const std::string& k : t.kinds) std::printf("    %s\n", k.c_str());
    EXPECT_EQ(t.nonfinite, 0) << t.technique;
    EXPECT_EQ(t.inconsistent, 0) << t.technique;
    EXPECT_GE(t.cases, 1000) << t.technique;
    EXPECT_GT(t.covered, 0) << t.technique;
  }
  EXPECT_EQ(r.techniques.size(), 7u);
  std::printf("hard sweeps: %.1f s\n", r.seconds);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
