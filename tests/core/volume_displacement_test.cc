#include "core/volume_displacement.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "core/error.h"

namespace core {
namespace {

using K = DeformationKind;

// The deformations these tests were written for (Correa 2006's figures),
// in the one vocabulary (core::kDeformationTable): pull of amplitude 1 and
// sigma 0.15; a peel of 160 degrees of the layer 0.8 <= z <= 0.9 (T = 0.1);
// slices of period 0.25 and gap 0.06; a seam opening to 0.2 from z = 0.3;
// a wave of amplitude 0.05 and wavelength 0.5; the table's defaults else.
Deformation Options(K kind) {
  Deformation d = Deformation::Default(kind);
  switch (kind) {
    case K::kPull:
      d.amount = 1.0, d.width = 0.15;
      break;
    case K::kPeel:
      d.amount = 160 * M_PI / 180, d.width = 0.1;
      break;
    case K::kSeam:
      d.amount = 0.2, d.width = 0.7;
      break;
    default:
      break;
  }
  return d;
}
std::string EffectName(K kind) { return DeformationKindName(kind); }
glm::dvec4 EvaluateEffect(const Deformation& d, const glm::dvec3& u) {
  return EvaluateVolumeMap(d, u);
}
DisplacementMap SampleEffect(const Deformation& d, const glm::ivec3& dims, int smooth = 1) {
  return SampleDeformationMap(d, dims, smooth);
}

TEST(VolumeDisplacement, GaussianPullMatchesEq8AtTheCentreAndVanishesOnTheXYFaces) {
  const Deformation o = Options(K::kPull);
  // Sec. 5: "the point (32,32,32) ... (0.5,0.5,0.5) ... contains (0,0,-0.5)".
  const glm::dvec4 c = EvaluateEffect(o, {0.5, 0.5, 0.5});
  EXPECT_DOUBLE_EQ(c.x, 0);
  EXPECT_DOUBLE_EQ(c.y, 0);
  EXPECT_DOUBLE_EQ(c.z, -0.5);
  EXPECT_DOUBLE_EQ(c.w, 1);
  // Scaled by z, zero on the XY boundary of the unit cube.
  EXPECT_DOUBLE_EQ(EvaluateEffect(o, {0.5, 0.5, 1.0}).z, -1.0);
  for (double t = 0; t <= 1; t += 0.125) {
    for (double z : {0.25, 1.0}) {
      EXPECT_EQ(EvaluateEffect(o, {0, t, z}).z, 0);
      EXPECT_EQ(EvaluateEffect(o, {1, t, z}).z, 0);
      EXPECT_EQ(EvaluateEffect(o, {t, 0, z}).z, 0);
      EXPECT_EQ(EvaluateEffect(o, {t, 1, z}).z, 0);
    }
  }
  // The map at 64 texels a box unit (the text's size; Table 2 says 32^3) at
  // the box centre: the trilinear mean of the four texels around the centre
  // line, whose centres are half a texel off it, so g is slightly below 1
  // there. The map reaches above the box (the pulled top: VolumeMapBox), so
  // the box centre is at map coordinate z < 0.5 and D is in map units.
  const glm::dmat4 box_from_map = BoxFromMap(o);
  EXPECT_GT(box_from_map[2][2], 2.0);  // the top rises by the amplitude, 1
  EXPECT_EQ(VolumeMapDims(o, 64),
            glm::ivec3(64, 64, static_cast<int>(std::ceil(64 * box_from_map[2][2]))));
  const DisplacementMap map = SampleEffect(o, VolumeMapDims(o, 64));
  const glm::dvec3 centre(glm::inverse(box_from_map) * glm::dvec4(0.5, 0.5, 0.5, 1.0));
  glm::dvec4 s = SampleMap(map, centre);
  s.z *= box_from_map[2][2];
  const double r = std::sqrt(2.0) * 0.5 / 64;
  const double g = (std::exp(-r * r / (2 * 0.15 * 0.15)) - std::exp(-0.25 / (2 * 0.15 * 0.15))) /
                   (1 - std::exp(-0.25 / (2 * 0.15 * 0.15)));
  EXPECT_NEAR(s.z, -0.5 * g, 1e-6);
  EXPECT_NEAR(s.z, -0.5, 2e-3);
}

// For maps with a closed-form forward F: p' = F(p) is shown at p, with
// alpha 1 (every object point has its image, sec. 4.1).
TEST(VolumeDisplacement, InverseMapsUndoTheForwardMaps) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (K e : {K::kPeel, K::kSlices, K::kSeam}) {
    const Deformation o = Options(e);
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
      // Object points (the peel's: below its top, 0.9, where the map removes
      // what the flap does not cover).
      const glm::dvec3 p(u(rng), u(rng), e == K::kPeel ? 0.9 * u(rng) : u(rng));
      const glm::dvec3 pp = o.ForwardInBox(p);
      if (pp.x < 0 || pp.x > 1 || pp.z < 0 || pp.z > 1) continue;
      const glm::dvec4 d = EvaluateEffect(o, pp);
      ASSERT_EQ(d.w, 1) << EffectName(e) << " p " << p.x << " " << p.y << " " << p.z;
      ASSERT_NEAR(glm::length(pp + glm::dvec3(d) - p), 0, 1e-12) << EffectName(e);
      ++checked;
    }
    EXPECT_GT(checked, 10000) << EffectName(e);
  }
}

// Correa 2006 sec. 4: material a deformation moves out of the volume's box
// is still drawn. For every kind but the peel (its own rule: the map reaches
// z = 1.5), at its defaults and at larger amounts: every object point p of
// the box, moved to p' (the closed-form forward, or for pull and wave the
// fixed point of p' = p - D(p'), which converges as |dD/dz| < 1), lies in
// the map's box (VolumeMapBox, the proxy the pass draws), and the map as
// sampled on its grid shows p there, also where p' is outside [0, 1]^3.
TEST(VolumeDisplacement, MapBoxesHoldTheMaterialTheDeformationsMove) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Deformation> cases;
  for (const DeformationInfo& info : kDeformationTable) {
    if (info.kind == K::kPeel) continue;
    cases.push_back(Deformation::Default(info.kind));
  }
  Deformation twist = Deformation::Default(K::kTwist);
  twist.amount = 0.25 * M_PI, twist.width = 0;
  cases.push_back(twist);
  Deformation pull = Deformation::Default(K::kPull);
  pull.amount = 0.8, pull.width = 0.2;
  cases.push_back(pull);
  Deformation slices = Deformation::Default(K::kSlices);
  slices.amount = 0.1, slices.width = 0.2;
  cases.push_back(slices);
  for (const Deformation& d : cases) {
    const std::string label = fmt::format("{} {} {}", EffectName(d.kind), d.amount, d.width);
    const Box3d box = VolumeMapBox(d);
    const glm::dmat4 map_from_box = glm::inverse(BoxFromMap(d));
    const DisplacementMap map = SampleEffect(d, VolumeMapDims(d, 64), 0);
    const glm::dvec3 texel = glm::dvec3(box.hi - box.lo) / glm::dvec3(map.dims);
    int outside = 0, shown = 0;
    double worst_moved = 0;
    for (int i = 0; i < 20000; ++i) {
      const glm::dvec3 p(u01(rng), u01(rng), u01(rng));
      glm::dvec3 pp = p;
      if (d.HasForward()) {
        pp = d.ForwardInBox(p);
      } else {
        for (int k = 0; k < 200; ++k) pp = p - glm::dvec3(d.EvaluateInBox(pp));
      }
      worst_moved = std::max(worst_moved, glm::length(pp - p));
      ASSERT_TRUE(box.Contains(pp)) << label << ": p " << p.x << " " << p.y << " " << p.z
                                    << " moves to " << pp.x << " " << pp.y << " " << pp.z;
      const bool out = pp.x < 0 || pp.x > 1 || pp.y < 0 || pp.y > 1 || pp.z < 0 || pp.z > 1;
      outside += out;
      if (d.IsCutAway() || !out) continue;
      // Where the map is smooth (a texel and a half from a cut or a slab's
      // edge the trilinear footprint straddles two pre-images).
      const glm::dvec3 m(map_from_box * glm::dvec4(pp, 1.0));
      const glm::dvec4 sampled = SampleMap(map, m);
      bool near_cut = false;
      for (int a = 0; a < 3 && !near_cut; ++a) {
        for (double s : {-1.5, 1.5}) {
          glm::dvec3 q = pp;
          q[a] += s * texel[a];
          near_cut = near_cut || EvaluateEffect(d, q).w < 1 ||
                     glm::length(glm::dvec3(EvaluateEffect(d, q)) -
                                 glm::dvec3(EvaluateEffect(d, pp))) > 4 * glm::length(texel);
        }
      }
      if (near_cut) continue;
      const glm::dvec3 d_box = glm::dvec3(BoxFromMap(d) * glm::dvec4(glm::dvec3(sampled), 0.0));
      EXPECT_NEAR(glm::length(pp + d_box - p), 0, 2 * glm::length(texel)) << label;
      EXPECT_GT(sampled.w, 0.5) << label;
      ++shown;
    }
    std::printf(
        "%s: map box [%.3f %.3f %.3f]-[%.3f %.3f %.3f], %d of 20000 points moved out of "
        "the volume's box, %d checked on the map, largest move %.3f\n",
        label.c_str(), box.lo.x, box.lo.y, box.lo.z, box.hi.x, box.hi.y, box.hi.z, outside, shown,
        worst_moved);
    if (d.IsCutAway()) {
      EXPECT_EQ(outside, 0) << label;  // they remove, never move
      EXPECT_EQ(box, (Box3d{glm::dvec3(0.0), glm::dvec3(1.0)})) << label;
    }
  }
  // The twist is rigid inside its radius and fades to the identity at r =
  // 0.5, so its faces (and corners) stay put: its map is the box itself.
  EXPECT_EQ(VolumeMapBox(twist), (Box3d{glm::dvec3(0.0), glm::dvec3(1.0)}));
  // A pull lifts material (p' = p - D, D.z <= 0): only the top grows, by the
  // amplitude; the slices spread to +x only, up to the last slab's shift.
  const Box3d lifted = VolumeMapBox(pull);
  EXPECT_EQ(lifted.lo, glm::dvec3(0.0));
  EXPECT_NEAR(lifted.hi.z, 1.0 + pull.amount + 1.0 / 64, 0.01);
  const Box3d spread = VolumeMapBox(slices);
  EXPECT_EQ(spread.lo, glm::dvec3(0.0));
  EXPECT_NEAR(spread.hi.x, 1.0 + 10 * slices.amount + 1.0 / 64, 1e-9);
}

// Cuts: space with no pre-image has alpha 0, and D stays continuous there
// (sec. 4.1: the pseudo-inverse). Continuity as a number: the largest change
// of D between neighbour texels halves when the grid doubles (a jump would
// stay the same size at any resolution).
float WorstNeighbourStep(const DisplacementMap& map, size_t* cut) {
  float worst = 0;
  const glm::ivec3 n = map.dims;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        *cut += map.at(x, y, z).w == 0;
        const glm::vec3 d(map.at(x, y, z));
        if (x + 1 < n.x) worst = std::max(worst, glm::length(glm::vec3(map.at(x + 1, y, z)) - d));
        if (y + 1 < n.y) worst = std::max(worst, glm::length(glm::vec3(map.at(x, y + 1, z)) - d));
        if (z + 1 < n.z) worst = std::max(worst, glm::length(glm::vec3(map.at(x, y, z + 1)) - d));
      }
  return worst;
}

TEST(VolumeDisplacement, CutsHaveAlphaZeroAndAContinuousPseudoInverse) {
  for (K e : {K::kSlices, K::kSeam, K::kPeel}) {
    size_t cut32 = 0, cut64 = 0;
    const float w32 = WorstNeighbourStep(SampleEffect(Options(e), {32, 8, 32}, 0), &cut32);
    const float w64 = WorstNeighbourStep(SampleEffect(Options(e), {64, 16, 64}, 0), &cut64);
    EXPECT_GT(cut64, 1000u) << EffectName(e);
    EXPECT_LE(w64, 0.6f * w32) << EffectName(e) << ": worst step 32^3 " << w32 << ", 64^3 " << w64;
    std::printf("%s: worst neighbour step of D at 32: %.4f, at 64: %.4f\n", EffectName(e).c_str(),
                w32, w64);
  }
}

TEST(VolumeDisplacement, SixteenBitStorageCutsTheBoundaryErrorOver10xAgainst8Bit) {
  const DisplacementMap map = SampleEffect(Options(K::kPeel), {64, 64, 64});
  double worst[3] = {0, 0, 0};
  const int bits[3] = {8, 16, 32};
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  DisplacementMap stored[3];
  for (int b = 0; b < 3; ++b)
    stored[b] = DequantizeDisplacementMap(StoreDisplacementMap(map, bits[b]));
  int near_cut = 0;
  for (int i = 0; i < 200000; ++i) {
    const glm::dvec3 p(u(rng), u(rng), u(rng));
    const glm::dvec4 exact = SampleMap(map, p);
    if (std::abs(exact.w - 0.5) > 0.2) continue;  // the boundary of a cut
    ++near_cut;
    for (int b = 0; b < 3; ++b) {
      worst[b] =
          std::max(worst[b], glm::length(glm::dvec3(SampleMap(stored[b], p)) - glm::dvec3(exact)));
    }
  }
  EXPECT_GT(near_cut, 1000);
  const double scale = map.MaxAbsDisplacement();
  // Rounding error of one component: half a step, step = 2 scale / (2^bits - 1).
  EXPECT_LE(worst[0], std::sqrt(3.0) * scale / 255 * 1.01);
  EXPECT_LE(worst[1], std::sqrt(3.0) * scale / 65535 * 1.01);
  EXPECT_LE(worst[2], 1e-6);
  EXPECT_GE(worst[0] / worst[1], 10.0) << "8-bit " << worst[0] << " 16-bit " << worst[1];
  RecordProperty("boundary_error_8bit", std::to_string(worst[0]));
  RecordProperty("boundary_error_16bit", std::to_string(worst[1]));
  std::printf("boundary position error (map units): 8-bit %.3g, 16-bit %.3g, ratio %.0f\n",
              worst[0], worst[1], worst[0] / worst[1]);
}

TEST(VolumeDisplacement, PlacementAndCompositionFollowEq9And10) {
  Deformation wave = Options(K::kWave);
  wave.amount = 0.1;
  const DisplacementMap w = SampleEffect(wave, {32, 8, 8});
  const DisplacementMap pull = SampleEffect(Options(K::kPull), {16, 16, 16});
  // Eq. 10 with M = translate(0.25) * scale(0.5): p = p' + A D(M^-1 p').
  const glm::dmat4 m =
      glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(0.25)), glm::dvec3(0.5));
  const glm::dvec3 pp(0.4, 0.5, 0.6);
  const DisplacedSample s = Displace({{&w, m}}, pp);
  const glm::dvec3 u = (pp - 0.25) / 0.5;
  EXPECT_NEAR(glm::length(s.p - (pp + 0.5 * glm::dvec3(SampleMap(w, u)))), 0, 1e-12);
  // Outside the placed cube: identity.
  EXPECT_EQ(Displace({{&w, m}}, {0.1, 0.5, 0.5}).p, glm::dvec3(0.1, 0.5, 0.5));
  // Eq. 9: the last map acts first; composition does not commute.
  const DisplacedSample ab = Displace({{&w, glm::dmat4(1.0)}, {&pull, glm::dmat4(1.0)}}, pp);
  const glm::dvec3 after_pull = pp + glm::dvec3(SampleMap(pull, pp));
  EXPECT_NEAR(glm::length(ab.p - (after_pull + glm::dvec3(SampleMap(w, after_pull)))), 0, 1e-12);
  const DisplacedSample ba = Displace({{&pull, glm::dmat4(1.0)}, {&w, glm::dmat4(1.0)}}, pp);
  EXPECT_GT(glm::length(ab.p - ba.p), 1e-4);
}

// Affine D fields are reproduced exactly by trilinear filtering between the
// texel centres, so the chained Jacobian of eq. 9-10 must be exact there.
DisplacementMap AffineMap(const glm::dmat3& j, const glm::ivec3& dims) {
  DisplacementMap map;
  map.dims = dims;
  map.texels.resize(static_cast<size_t>(dims.x) * dims.y * dims.z);
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const glm::dvec3 u((x + 0.5) / dims.x, (y + 0.5) / dims.y, (z + 0.5) / dims.z);
        map.at(x, y, z) = glm::vec4(glm::vec3(j * (u - 0.5)), 1.0f);
      }
  return map;
}

TEST(VolumeDisplacement, ChainedJacobianIsExactForAffineMaps) {
  glm::dmat3 j1(0.0), j2(0.0);
  j1[0][2] = 0.25;  // D1 = (0, 0, 0.25 x): a shear
  j2[1][0] = -0.5;  // D2 = (-0.5 y, 0, 0)
  j2[2][2] = 0.125;
  // float texels: exact only to float rounding.
  const DisplacementMap m1 = AffineMap(j1, {8, 8, 8}), m2 = AffineMap(j2, {8, 8, 8});
  const glm::dmat4 place = glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(0.1, 0.2, 0.0)),
                                      glm::dvec3(0.8, 0.5, 1.0));
  const glm::dmat3 a(place);
  const glm::dvec3 pp(0.5, 0.45, 0.5);
  const DisplacedSample s =
      Displace({{&m1, glm::dmat4(1.0)}, {&m2, place}}, pp, /*with_jacobian=*/true);
  const glm::dmat3 expect = (glm::dmat3(1.0) + j1) * (glm::dmat3(1.0) + a * j2 * glm::inverse(a));
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(s.jacobian[c][r], expect[c][r], 1e-5) << c << r;
}

TEST(VolumeDisplacement, NormalTransformsOfAShearAreExact) {
  // D = (0, 0, 0.3 x): J_D has one entry; the normal transform of eq. 6 (sec.
  // 4.3.1) is B = (I + J_D)^T per texel.
  DisplacementMap map;
  map.dims = {8, 4, 4};
  map.texels.resize(8 * 4 * 4);
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 8; ++x) map.at(x, y, z) = {0, 0, 0.3f * (x + 0.5f) / 8, 1};
  const MapDerivatives d = ComputeMapDerivatives(map);
  for (const glm::mat3& jd : d.jacobian) {
    const glm::mat3 m = glm::transpose(glm::mat3(1.0f) + jd);
    EXPECT_NEAR(m[2][0], 0.3f, 1e-5);  // column z, row x of the transpose
    EXPECT_NEAR(m[0][2], 0.0f, 1e-6);
    EXPECT_NEAR(m[0][0], 1.0f, 1e-6);
  }
}

TEST(VolumeDisplacement, MapDerivativesOfLinearFieldsAreExactAtEveryTexel) {
  // D = (0.2 y, -0.1 z, 0.3 x), alpha = 0.5 + 0.25 z: linear, so central and
  // one-sided differences are both exact, faces included.
  DisplacementMap map;
  map.dims = {6, 5, 4};
  map.texels.resize(6 * 5 * 4);
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 6; ++x) {
        const glm::vec3 u((x + 0.5f) / 6, (y + 0.5f) / 5, (z + 0.5f) / 4);
        map.at(x, y, z) = {0.2f * u.y, -0.1f * u.z, 0.3f * u.x, 0.5f + 0.25f * u.z};
      }
  const MapDerivatives d = ComputeMapDerivatives(map);
  ASSERT_EQ(d.jacobian.size(), map.texels.size());
  glm::mat3 expect(0.0f);
  expect[1][0] = 0.2f;   // dDx/dy
  expect[2][1] = -0.1f;  // dDy/dz
  expect[0][2] = 0.3f;   // dDz/dx
  for (size_t i = 0; i < d.jacobian.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) ASSERT_NEAR(d.jacobian[i][c][r], expect[c][r], 1e-5) << i;
    ASSERT_NEAR(d.alpha_gradient[i].x, 0.0f, 1e-5);
    ASSERT_NEAR(d.alpha_gradient[i].y, 0.0f, 1e-5);
    ASSERT_NEAR(d.alpha_gradient[i].z, 0.25f, 1e-5);
  }
}

TEST(VolumeDisplacement, ActiveBoxHoldsEveryTexelThatMovesAnything) {
  DisplacementMap map;
  map.dims = {10, 8, 16};
  map.texels.assign(10 * 8 * 16, glm::vec4(0, 0, 0, 1));
  for (int bits : {8, 16, 32}) {
    const Box3 none = ActiveBox(StoreDisplacementMap(map, bits));
    EXPECT_GT(none.lo.x, none.hi.x) << bits;  // the identity everywhere: empty
  }
  map.at(4, 3, 7) = {0.0f, 0.0f, 0.2f, 1.0f};  // one texel moves
  map.at(5, 3, 7) = {0.0f, 0.0f, 0.0f, 0.3f};  // one is cut
  for (int bits : {8, 16, 32}) {
    const Box3 b = ActiveBox(StoreDisplacementMap(map, bits));
    // Texels 4..5, 3, 7 grown by two texels each side.
    EXPECT_NEAR(b.lo.x, 2.0 / 10, 1e-12) << bits;
    EXPECT_NEAR(b.hi.x, 8.0 / 10, 1e-12) << bits;
    EXPECT_NEAR(b.lo.y, 1.0 / 8, 1e-12) << bits;
    EXPECT_NEAR(b.hi.y, 6.0 / 8, 1e-12) << bits;
    EXPECT_NEAR(b.lo.z, 5.0 / 16, 1e-12) << bits;
    EXPECT_NEAR(b.hi.z, 10.0 / 16, 1e-12) << bits;
  }
  map.at(0, 0, 0) = {0.1f, 0.0f, 0.0f, 1.0f};  // clipped to the cube
  const Box3 c = ActiveBox(StoreDisplacementMap(map, 16));
  EXPECT_EQ(c.lo, glm::dvec3(0.0));
  // Every texel outside the box reads as the identity after storage.
  const DisplacementMap back = DequantizeDisplacementMap(StoreDisplacementMap(map, 16));
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 10; ++x) {
        const glm::dvec3 u((x + 0.5) / 10, (y + 0.5) / 8, (z + 0.5) / 16);
        if (glm::all(glm::greaterThanEqual(u, c.lo)) && glm::all(glm::lessThanEqual(u, c.hi)))
          continue;
        EXPECT_LT(glm::length(glm::vec3(back.at(x, y, z))), 1e-4f);
        EXPECT_EQ(back.at(x, y, z).w, 1.0f);
      }
}

// Every sample in an identity brick reads the identity (as stored: 16 bits
// round 0 to 1.5e-5 of the scale), and so do the samples half a texel away
// that the derivatives difference; every sample in a cut brick is
// transparent; the bricks tile ActiveBox. Brute force over random points of
// every brick, five effects, three storages, two sizes.
TEST(VolumeDisplacement, MapBricksHoldWhatEverySampleInThemReads) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u01(0, 1);
  int counts[3] = {0, 0, 0};
  for (const DeformationInfo& info : kDeformationTable) {
    const K effect = info.kind;
    const Deformation o = Options(effect);
    for (const int n : {32, 64}) {
      const DisplacementMap map = SampleEffect(o, {n, n, n});
      for (const int bits : {8, 16, 32}) {
        const StoredDisplacementMap stored = StoreDisplacementMap(map, bits);
        const DisplacementMap read = DequantizeDisplacementMap(stored);
        const double zero = bits == 32 ? 0.0 : 1.6e-5 * stored.scale;
        const MapBricks bricks = ClassifyMapBricks(stored, 4);
        const Box3 active = ActiveBox(stored);
        for (int a = 0; a < 3; ++a) {
          EXPECT_DOUBLE_EQ(bricks.Edge(a, 0), active.lo[a]);
          EXPECT_DOUBLE_EQ(bricks.Edge(a, bricks.grid[a]), active.hi[a]);
        }
        const glm::dvec3 texel(1.0 / n);
        for (int z = 0; z < bricks.grid.z; ++z)
          for (int y = 0; y < bricks.grid.y; ++y)
            for (int x = 0; x < bricks.grid.x; ++x) {
              const MapBrickKind kind =
                  bricks.kinds[(static_cast<size_t>(z) * bricks.grid.y + y) * bricks.grid.x + x];
              ++counts[static_cast<int>(kind)];
              if (bits == 8) {
                EXPECT_NE(kind, MapBrickKind::kIdentity);
              }
              const glm::dvec3 lo(bricks.Edge(0, x), bricks.Edge(1, y), bricks.Edge(2, z));
              const glm::dvec3 hi(bricks.Edge(0, x + 1), bricks.Edge(1, y + 1),
                                  bricks.Edge(2, z + 1));
              for (int q = 0; q < 12; ++q) {
                // Corners and faces too: the first eight points are corners.
                glm::dvec3 p;
                for (int a = 0; a < 3; ++a)
                  p[a] =
                      q < 8 ? ((q >> a) & 1 ? hi[a] : lo[a]) : lo[a] + u01(rng) * (hi[a] - lo[a]);
                if (kind == MapBrickKind::kCut) {
                  EXPECT_LT(SampleMap(read, p).w, 0.5) << EffectName(effect) << " " << n;
                  continue;
                }
                if (kind != MapBrickKind::kIdentity) continue;
                for (int k = -1; k < 3; ++k) {
                  glm::dvec3 at = p;
                  if (k >= 0) at[k] += (q % 2 ? 0.5 : -0.5) * texel[k];
                  const glm::dvec4 v = SampleMap(read, at);
                  EXPECT_LE(glm::length(glm::dvec3(v)), 2 * zero) << EffectName(effect) << " " << n;
                  EXPECT_NEAR(v.w, 1.0, 1e-12) << EffectName(effect) << " " << n;
                }
              }
            }
      }
    }
  }
  std::printf("map bricks: %d identity, %d cut, %d displaced\n", counts[0], counts[1], counts[2]);
  EXPECT_GT(counts[0], 100);
  EXPECT_GT(counts[1], 10);
  // A map that is the identity everywhere has no bricks.
  DisplacementMap identity;
  identity.dims = {8, 8, 8};
  identity.texels.assign(512, glm::vec4(0, 0, 0, 1));
  EXPECT_EQ(ClassifyMapBricks(StoreDisplacementMap(identity, 16), 4).grid, glm::ivec3(0));
}

TEST(VolumeDisplacement, ProxyBoxHoldsTheObjectAndThePlacedMaps) {
  const DisplacementMap pull = SampleEffect(Options(K::kPull), {4, 4, 4});
  const glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 0, 0));
  const Box3 box = ProxyBox({glm::dvec3(0), glm::dvec3(1)}, {{&pull, m}});
  EXPECT_EQ(box.lo, glm::dvec3(0));
  EXPECT_EQ(box.hi, glm::dvec3(1.5, 1, 1));
}

// The cut-aways on volumes: the same regions as the mesh deformations of
// the same names (core::CutAwayAlpha), nothing moved, alpha 0 inside.
TEST(VolumeDisplacement, CutAwaysRemoveTheirRegionAndMoveNothing) {
  Deformation o = Options(K::kClip);
  o.amount = 0.7;
  EXPECT_EQ(EvaluateEffect(o, {0.2, 0.4, 0.8}), glm::dvec4(0, 0, 0, 0));
  EXPECT_EQ(EvaluateEffect(o, {0.2, 0.4, 0.6}), glm::dvec4(0, 0, 0, 1));
  o = Options(K::kCutaway);
  EXPECT_EQ(EvaluateEffect(o, {0.6, 0.6, 0.6}).w, 0);
  EXPECT_EQ(EvaluateEffect(o, {0.6, 0.4, 0.6}).w, 1);
  o = Options(K::kWedge);
  o.amount = 60 * M_PI / 180;
  EXPECT_EQ(EvaluateEffect(o, {0.9, 0.55, 0.5}).w, 0);  // 7 degrees off +x
  EXPECT_EQ(EvaluateEffect(o, {0.6, 0.7, 0.5}).w, 1);   // 63 degrees off +x
  EXPECT_EQ(o.ForwardInBox({0.9, 0.55, 0.5}), glm::dvec3(0.9, 0.55, 0.5));
  EXPECT_EQ(DeformationKindFromName("wedge"), K::kWedge);
  o.amount = 200 * M_PI / 180;
  EXPECT_THROW(o.Check(), InputError);
  o = Options(K::kCutaway);
  o.amount = -0.1;
  EXPECT_THROW(o.Check(), InputError);
}

TEST(VolumeDisplacement, BadOptionsAreInputErrors) {
  Deformation o = Options(K::kPeel);
  o.amount = std::nan("");
  EXPECT_THROW(o.Check(), InputError);
  o = Options(K::kSlices);
  o.amount = o.width;
  EXPECT_THROW(o.Check(), InputError);
  EXPECT_THROW(DeformationKindFromName("melt"), InputError);
  EXPECT_EQ(DeformationKindFromName("seam"), K::kSeam);
  EXPECT_THROW(StoreDisplacementMap(SampleEffect(Options(K::kPull), {2, 2, 2}), 12), InputError);
}

}  // namespace
}  // namespace core
