// core/deformation: inverse displacements against their closed-form forward
// maps, vanishing faces, the cut alpha, sums, placement (eq. 2) and the
// sampled texture.
#include "core/deformation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/distance_field.h"
#include "core/error.h"

namespace core {
namespace {

Deformation Make(DeformationKind kind, double amount, double width) {
  Deformation d;
  d.kind = kind;
  d.amount = amount;
  d.width = width;
  d.Check();
  return d;
}

TEST(Deformation, InverseUndoesTheForwardMap) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (const Deformation& d :
       {Make(DeformationKind::kTwist, 2.5, 0.3), Make(DeformationKind::kTwist, -1.0, 0.0),
        Make(DeformationKind::kBend, 1.2, 0), Make(DeformationKind::kBend, -0.8, 0),
        Make(DeformationKind::kKnife, 0.2, 0.6)}) {
    double worst = 0.0;
    int tested = 0;
    for (int n = 0; n < 2000; ++n) {
      glm::dvec3 u(u01(rng), u01(rng), u01(rng));
      glm::dvec3 p = d.Forward(u);
      if (glm::any(glm::lessThan(p, glm::dvec3(0.0))) ||
          glm::any(glm::greaterThan(p, glm::dvec3(1.0)))) {
        continue;  // left the box: D is only defined inside
      }
      if (d.kind == DeformationKind::kKnife && u.x == 0.5) continue;
      glm::dvec3 back = p + glm::dvec3(d.Evaluate(p));
      worst = std::max(worst, glm::length(back - u));
      ++tested;
    }
    EXPECT_GT(tested, 500) << DeformationKindName(d.kind);
    EXPECT_LT(worst, 1e-12) << DeformationKindName(d.kind) << " amount " << d.amount;
  }
}

// Max |D| over a face of the box (axis a at value v), on a 33 x 33 grid.
double MaxOnFace(const Deformation& d, int axis, double value) {
  double worst = 0.0;
  for (int i = 0; i <= 32; ++i)
    for (int j = 0; j <= 32; ++j) {
      glm::dvec3 u;
      u[axis] = value;
      u[(axis + 1) % 3] = i / 32.0;
      u[(axis + 2) % 3] = j / 32.0;
      worst = std::max(worst, glm::length(glm::dvec3(d.Evaluate(u))));
    }
  return worst;
}

TEST(Deformation, VanishesOnTheFacesItMust) {
  Deformation twist = Make(DeformationKind::kTwist, 3.0, 0.35);
  EXPECT_LT(MaxOnFace(twist, 2, 0.0), 1e-15);
  for (int axis : {0, 1}) {
    for (double v : {0.0, 1.0}) EXPECT_LT(MaxOnFace(twist, axis, v), 1e-15) << axis << " " << v;
  }
  EXPECT_GT(MaxOnFace(twist, 2, 1.0), 0.1);  // the top turns (the paper's exception)
  for (const Deformation& d :
       {Make(DeformationKind::kBend, 1.0, 0), Make(DeformationKind::kPull, 0.5, 0.03),
        Make(DeformationKind::kKnife, 0.2, 0.5)}) {
    EXPECT_LT(MaxOnFace(d, 2, 0.0), 1e-15) << DeformationKindName(d.kind);
  }
  // The narrow pull is negligible on the sides: exp(-1/(8 w^2)) * amplitude.
  Deformation pull = Make(DeformationKind::kPull, 0.5, 0.03);
  for (int axis : {0, 1}) EXPECT_LT(MaxOnFace(pull, axis, 0.0), 1e-30);
}

TEST(Deformation, PullMatchesTheFigure3Values) {
  // Correa 2006 (notes): on the axis at z = 0.5, amplitude 1 gives D = (0, 0, -0.5).
  glm::dvec4 e = Make(DeformationKind::kPull, 1.0, 0.03).Evaluate({0.5, 0.5, 0.5});
  EXPECT_NEAR(e.z, -0.5, 1e-15);
  EXPECT_EQ(e.x, 0.0);
  EXPECT_EQ(e.w, -1.0);  // no cut
}

TEST(Deformation, KnifeAlphaMarksTheGap) {
  Deformation knife = Make(DeformationKind::kKnife, 0.2, 0.5);
  EXPECT_NEAR(knife.Evaluate({0.5, 0.3, 1.0}).w, 0.1, 1e-15);   // middle of the gap at the top
  EXPECT_LT(knife.Evaluate({0.65, 0.3, 1.0}).w, 0.0);           // outside the gap
  EXPECT_LE(knife.Evaluate({0.5, 0.3, 0.4}).w, 0.0);            // below the blade: not cut
  EXPECT_NEAR(knife.Evaluate({0.6, 0.3, 0.4}).w, -0.1, 1e-15);  // -|x - 0.5| there (Lipschitz)
  EXPECT_NEAR(knife.Evaluate({0.55, 0.3, 0.75}).w, 0.0,
              1e-15);  // on the gap's face (w = 0.1 there)
  // The gap's material collapses onto x = 0.5: D continuous across its face.
  glm::dvec4 in = knife.Evaluate({0.6 - 1e-9, 0.3, 1.0}),
             out = knife.Evaluate({0.6 + 1e-9, 0.3, 1.0});
  EXPECT_NEAR(in.x, out.x, 1e-8);
}

TEST(Deformation, PeelTurnsTheFlapAndCutsTheSlabItLeft) {
  // Flap: x >= 0.5, 0.6 <= z <= 0.8 (T = 0.2), hinge x = 0.5, z = 0.8.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (double angle : {0.4, M_PI / 2, 2.5, M_PI}) {
    Deformation peel = Make(DeformationKind::kPeel, angle, 0.2);
    double worst = 0.0;
    int tested = 0;
    for (int n = 0; n < 2000; ++n) {
      // A point of the flap, turned; inside the box it maps back to itself.
      glm::dvec3 u(0.5 + 0.5 * u01(rng), u01(rng), 0.6 + 0.2 * u01(rng));
      glm::dvec3 p = peel.Forward(u);
      if (glm::any(glm::lessThan(p, glm::dvec3(0.0))) ||
          glm::any(glm::greaterThan(p, glm::dvec3(1.0)))) {
        continue;
      }
      glm::dvec4 e = peel.Evaluate(p);
      worst = std::max(worst, glm::length(p + glm::dvec3(e) - u));
      EXPECT_LT(e.w, 0.0);  // the flap is material
      ++tested;
    }
    EXPECT_GT(tested, 200) << angle;
    EXPECT_LT(worst, 1e-12) << angle;
    EXPECT_LT(MaxOnFace(peel, 2, 0.0), 1e-15) << angle;
  }
  // Turned flat (pi): the flap lies on top of the hinge's other side, the
  // slab it left is cut, with A the distance to the slab's faces.
  Deformation peel = Make(DeformationKind::kPeel, M_PI, 0.2);
  EXPECT_NEAR(peel.Evaluate({0.8, 0.5, 0.7}).w, 0.1, 1e-12);
  EXPECT_NEAR(peel.Evaluate({0.52, 0.5, 0.7}).w, 0.02, 1e-12);
  EXPECT_LT(peel.Evaluate({0.3, 0.5, 0.7}).w, 0.0);  // beside the slab: untouched
  EXPECT_LT(peel.Evaluate({0.8, 0.5, 0.5}).w, 0.0);  // below it
  glm::dvec4 flap = peel.Evaluate({0.3, 0.5, 0.9});  // the turned flap, mirrored about the hinge
  EXPECT_NEAR(flap.x, 0.4, 1e-12);
  EXPECT_NEAR(flap.z, -0.2, 1e-12);
  EXPECT_TRUE(peel.HasCut());
  EXPECT_THROW(Make(DeformationKind::kPeel, 4.0, 0.2), InputError);
  EXPECT_THROW(Make(DeformationKind::kPeel, 1.0, 0.6), InputError);
  EXPECT_EQ(DeformationKindFromName("peel"), DeformationKind::kPeel);
}

TEST(Deformation, PeelPiecesAreContinuousAndAgreeWithThePseudoInverse) {
  // The sampled D must not jump (a jump interpolated over one texel maps
  // that band anywhere): per piece, neighbouring points 1e-4 apart differ by
  // at most ~|J| 1e-4 in D and 1e-4 in A (the flap's D is a rigid turn:
  // |J| <= 2). Where the flap's mask is <= 0 its D is the pseudo-inverse's
  // (Evaluate: the flap wins); elsewhere the rest's is, with the slab cut.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (double angle : {0.0, 0.7, 2.4, M_PI}) {
    DeformationSum sum;
    sum.terms = {Make(DeformationKind::kPeel, angle, 0.15)};
    ASSERT_EQ(sum.Pieces(), 2);
    double worst_jump = 0.0, worst_mismatch = 0.0;
    int flap = 0;
    for (int n = 0; n < 20000; ++n) {
      const glm::dvec3 u(u01(rng), u01(rng), u01(rng));
      const glm::dvec3 v =
          u + 1e-4 * glm::normalize(glm::dvec3(u01(rng), u01(rng), u01(rng)) - 0.5);
      for (int piece = 0; piece < 2; ++piece) {
        const glm::dvec4 a = sum.EvaluatePiece(u, piece), b = sum.EvaluatePiece(v, piece);
        worst_jump = std::max({worst_jump, glm::length(glm::dvec3(a) - glm::dvec3(b)) / 2e-4,
                               std::abs(a.w - b.w) / 1e-4});
      }
      const glm::dvec4 rest = sum.EvaluatePiece(u, 0), turned = sum.EvaluatePiece(u, 1);
      const glm::dvec4 single = sum.Evaluate(u);
      if (angle > 0 && turned.w < 0) {
        ++flap;
        worst_mismatch = std::max(worst_mismatch, glm::length(glm::dvec3(turned - single)));
      } else if (angle > 0) {
        worst_mismatch = std::max(worst_mismatch, glm::length(glm::dvec3(rest - single)));
        EXPECT_NEAR(rest.w, single.w, 1e-12);
      }
      EXPECT_LE(glm::length(glm::dvec3(rest)), 0.0);  // the rest stays in place
    }
    EXPECT_LT(worst_jump, 1.0 + 1e-6) << angle;
    EXPECT_LT(worst_mismatch, 1e-12) << angle;
    if (angle > 0) {
      EXPECT_GT(flap, 200) << angle;  // at 2.4 most of the flap has left the box
    }
  }
  // Without a peel there is one piece, piece 0 being Evaluate.
  DeformationSum twist;
  twist.terms = {Make(DeformationKind::kTwist, 1.0, 0.2)};
  EXPECT_EQ(twist.Pieces(), 1);
  const glm::dvec3 u(0.3, 0.6, 0.7);
  EXPECT_EQ(twist.EvaluatePiece(u, 0), twist.Evaluate(u));
  EXPECT_EQ(SampleDeformation(twist, 4).pieces, 1);
  DeformationSum peel;
  peel.terms = {Make(DeformationKind::kPeel, 1.0, 0.2)};
  const DeformationTexture t = SampleDeformation(peel, 4);
  EXPECT_EQ(t.pieces, 2);
  EXPECT_EQ(t.rgba.size(), size_t{2} * 4 * 4 * 4 * 4);
}

// One channel of one piece of a sampled texture (4 floats per node) as a
// grid over the unit box, whose Sample is GL's LINEAR lookup.
DistanceField Channel(const std::vector<float>& values, int res, int piece, int channel) {
  DistanceField grid;
  grid.size = glm::ivec3(res);
  grid.spacing = 1.0 / (res - 1);
  const size_t nodes = static_cast<size_t>(res) * res * res;
  grid.values.resize(nodes);
  for (size_t i = 0; i < nodes; ++i) grid.values[i] = values[(piece * nodes + i) * 4 + channel];
  return grid;
}

TEST(Deformation, AlphaComponentsRebuildTheAlphaAndInterpolateExactly) {
  // The components recombine to each piece's alpha everywhere; with one peel
  // its planes are affine, so the sampled texture interpolates each exactly
  // (where the interpolated alpha itself rounds the slab's edges: measured
  // beside them as the largest error of the interpolated alpha).
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const std::vector<DeformationSum> sums = {
      {{Make(DeformationKind::kPeel, 0.9, 0.15)}},
      {{Make(DeformationKind::kPeel, 2.4, 0.2), Make(DeformationKind::kKnife, 0.2, 0.5)}},
      {{Make(DeformationKind::kTwist, 1.0, 0.3), Make(DeformationKind::kPeel, 1.5, 0.1)}},
      {{Make(DeformationKind::kPeel, 0.5, 0.1), Make(DeformationKind::kPeel, 1.0, 0.2)}},
      {{Make(DeformationKind::kKnife, 0.2, 0.5)}}};
  for (size_t s = 0; s < sums.size(); ++s) {
    const DeformationSum& sum = sums[s];
    const int res = 17;
    const DeformationTexture t = SampleDeformation(sum, res);
    EXPECT_EQ(t.alpha_components.size(), sum.Pieces() == 2 ? t.rgba.size() : size_t{0}) << s;
    double worst_rebuild = 0.0, worst_plane = 0.0, worst_alpha = 0.0;
    std::vector<std::array<DistanceField, 4>> planes(sum.Pieces());  // components 0-2, alpha
    for (int piece = 0; piece < sum.Pieces() && s < 3; ++piece) {
      for (int a = 0; a < 3; ++a) planes[piece][a] = Channel(t.alpha_components, res, piece, a);
      planes[piece][3] = Channel(t.rgba, res, piece, 3);
    }
    for (int n = 0; n < 4000; ++n) {
      const glm::dvec3 u(u01(rng), u01(rng), u01(rng));
      for (int piece = 0; piece < sum.Pieces(); ++piece) {
        const glm::dvec4 c = sum.AlphaComponents(u, piece);
        worst_rebuild =
            std::max(worst_rebuild, std::abs(DeformationSum::AlphaFromComponents(c, piece) -
                                             sum.EvaluatePiece(u, piece).w));
        if (s >= 3) continue;  // planes only for a lone peel
        for (int a = 0; a < 3; ++a)
          worst_plane = std::max(worst_plane, std::abs(planes[piece][a].Sample(u) - c[a]));
        worst_alpha = std::max(
            worst_alpha, std::abs(planes[piece][3].Sample(u) - sum.EvaluatePiece(u, piece).w));
      }
    }
    std::printf("sum %zu: rebuild %.3g, planes interpolated %.3g, alpha interpolated %.3g\n", s,
                worst_rebuild, worst_plane, worst_alpha);
    EXPECT_EQ(worst_rebuild, 0.0) << s;
    if (s < 3) {
      EXPECT_LT(worst_plane, 1e-6) << s;  // float storage only
      EXPECT_GT(worst_alpha, 1e-3) << s;  // what the planes avoid
    }
  }
}

// Cut-aways move nothing and their alpha is the signed distance (box units)
// to the removed region's nearest face where one face is nearest.
TEST(Deformation, CutAwaysAreDistancesAndMoveNothing) {
  Deformation clip{DeformationKind::kClip, 0.6, 0.0};
  Deformation corner{DeformationKind::kCutaway, 0.5, 0.0};
  Deformation wedge{DeformationKind::kWedge, M_PI / 2, 0.2};
  EXPECT_EQ(clip.Evaluate({0.3, 0.9, 0.75}), glm::dvec4(0, 0, 0, 0.75 - 0.6));
  EXPECT_NEAR(clip.Evaluate({0.3, 0.9, 0.4}).w, -0.2, 1e-15);
  EXPECT_NEAR(corner.Evaluate({0.9, 0.8, 0.6}).w, 0.1, 1e-15);   // nearest face z = 0.5
  EXPECT_NEAR(corner.Evaluate({0.9, 0.2, 0.9}).w, -0.3, 1e-15);  // y below the corner
  // The wedge: +x inside (distance to its faces at +-45 degrees), -x and +y outside.
  EXPECT_NEAR(wedge.Evaluate({0.9, 0.5, 0.8}).w, 0.4 * std::sqrt(0.5), 1e-12);
  EXPECT_LT(wedge.Evaluate({0.1, 0.5, 0.8}).w, 0.0);
  EXPECT_NEAR(wedge.Evaluate({0.5, 0.9, 0.8}).w, -0.4 * std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(wedge.Evaluate({0.9, 0.5, 0.1}).w, -0.1, 1e-12);  // below its bottom
  // A half-space at pi: x > 0.5.
  Deformation half{DeformationKind::kWedge, M_PI, 0.0};
  EXPECT_NEAR(half.Evaluate({0.7, 0.1, 0.5}).w, 0.2, 1e-12);
  for (const Deformation& d : {clip, corner, wedge}) {
    EXPECT_TRUE(d.HasCut());
    EXPECT_TRUE(d.HasForward());
    EXPECT_EQ(d.Forward({0.3, 0.7, 0.2}), glm::dvec3(0.3, 0.7, 0.2));
    EXPECT_EQ(DeformationKindFromName(DeformationKindName(d.kind)), d.kind);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u01(0, 1);
    for (int i = 0; i < 200; ++i) {
      const glm::dvec3 a(u01(rng), u01(rng), u01(rng)), b(u01(rng), u01(rng), u01(rng));
      EXPECT_EQ(glm::dvec3(d.Evaluate(a)), glm::dvec3(0.0));
      // 1-Lipschitz: the cut's skip bound holds.
      EXPECT_LE(std::abs(d.Evaluate(a).w - d.Evaluate(b).w), glm::length(a - b) + 1e-12);
    }
  }
  EXPECT_THROW((Deformation{DeformationKind::kClip, 1.5, 0.0}.Check()), InputError);
  EXPECT_THROW((Deformation{DeformationKind::kWedge, 0.0, 0.0}.Check()), InputError);
  EXPECT_THROW((Deformation{DeformationKind::kWedge, 1.0, -0.1}.Check()), InputError);
}

TEST(Deformation, SumAddsDisplacementsAndTakesTheLargestAlpha) {
  DeformationSum sum{
      {Make(DeformationKind::kTwist, 1.0, 0.3), Make(DeformationKind::kKnife, 0.2, 0.5)}};
  glm::dvec3 u(0.45, 0.52, 0.9);
  glm::dvec4 a = sum.terms[0].Evaluate(u), b = sum.terms[1].Evaluate(u), s = sum.Evaluate(u);
  EXPECT_NEAR(glm::length(glm::dvec3(s) - glm::dvec3(a) - glm::dvec3(b)), 0.0, 1e-15);
  EXPECT_EQ(s.w, std::max(a.w, b.w));
  EXPECT_TRUE(sum.HasCut());
}

TEST(Deformation, JacobianOfTheTwistMatchesTheRotation) {
  // Inside the rigid radius D = R(-a z) v - v: dD/dx = R(-a z) - I in (x, y).
  DeformationSum sum{{Make(DeformationKind::kTwist, 2.0, 0.4)}};
  glm::dvec3 u(0.55, 0.45, 0.7);
  glm::dmat3 j = sum.Jacobian(u);
  double a = -2.0 * 0.7;
  EXPECT_NEAR(j[0][0], std::cos(a) - 1, 1e-8);
  EXPECT_NEAR(j[0][1], std::sin(a), 1e-8);
  EXPECT_NEAR(j[1][0], -std::sin(a), 1e-8);
  EXPECT_NEAR(j[2][2], 0.0, 1e-8);
}

TEST(Deformation, PlacementAppliesEquation2) {
  // A twist in a rotated, translated, scaled box: p = p' + M D(M^-1 p').
  DeformationSum sum{{Make(DeformationKind::kTwist, 1.5, 0.3)}};
  Placement placement =
      Placement::FromRegion({{-1, -2, 0}, {1, 2, 3}}, {10, 20, 30}, 1.2, {0.1, 0.2, 0.3});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u01(0.02, 0.98);
  for (int n = 0; n < 200; ++n) {
    glm::dvec3 u(u01(rng), u01(rng), u01(rng));
    glm::dvec3 p_def(placement.object_from_box * glm::dvec4(u, 1.0));
    glm::dvec4 r = DeformObjectPoint(sum, placement, p_def);
    glm::dvec3 expected(placement.object_from_box *
                        glm::dvec4(u + glm::dvec3(sum.Evaluate(u)), 1.0));
    EXPECT_NEAR(glm::length(glm::dvec3(r) - expected), 0.0, 1e-12);
  }
  // Outside the box the point is not deformed.
  glm::dvec3 far(50, 0, 0);
  EXPECT_EQ(glm::dvec3(DeformObjectPoint(sum, placement, far)), far);
  Box3d b = placement.ObjectBounds();
  EXPECT_GT(b.size().x, 2.0);
}

TEST(Deformation, TextureSamplesTheNodes) {
  DeformationSum sum{{Make(DeformationKind::kBend, 0.9, 0)}};
  DeformationTexture t = SampleDeformation(sum, 9);
  ASSERT_EQ(t.rgba.size(), 9u * 9 * 9 * 4);
  // Node (8, 3, 8) is u = (1, 3/8, 1).
  size_t node = ((8 * 9 + 3) * 9 + 8) * 4;
  glm::dvec4 e = sum.Evaluate({1.0, 3.0 / 8, 1.0});
  for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(t.rgba[node + c], static_cast<float>(e[c]));
  EXPECT_GT(t.max_displacement_box, 0.1);
  Placement placement = Placement::FromRegion({{0, 0, 0}, {2, 2, 2}});
  EXPECT_NEAR(MaxObjectDisplacement(sum, placement, 9), 2 * t.max_displacement_box, 1e-6);
}

// The new names (slices, seam, wave) invert their forward maps where they
// have one, and the table's defaults pass Check() for every name.
TEST(Deformation, EveryNameHasValidDefaultsAndSlicesSeamInvertTheirForwardMaps) {
  for (const DeformationInfo& info : kDeformationTable) {
    const Deformation d = Deformation::Default(info.kind);
    EXPECT_NO_THROW(d.Check()) << DeformationKindName(info.kind);
    EXPECT_EQ(DeformationKindFromName(DeformationKindName(info.kind)), info.kind);
  }
  std::mt19937 rng(33);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (DeformationKind kind : {DeformationKind::kSlices, DeformationKind::kSeam}) {
    const Deformation d = Deformation::Default(kind);
    for (int i = 0; i < 5000; ++i) {
      const glm::dvec3 p(u01(rng), u01(rng), u01(rng));
      const glm::dvec3 q = d.Forward(p);
      const glm::dvec4 e = d.Evaluate(q);
      ASSERT_LE(e.w, 0.0) << DeformationKindName(kind);  // a point's image is never cut
      ASSERT_NEAR(glm::length(q + glm::dvec3(e) - p), 0.0, 1e-12) << DeformationKindName(kind);
    }
  }
  // The wave: D.z = amount sin(2 pi x / width), nothing cut.
  const Deformation wave = Deformation::Default(DeformationKind::kWave);
  EXPECT_NEAR(wave.Evaluate({0.125, 0.3, 0.7}).z, wave.amount * std::sin(2 * M_PI * 0.125 / 0.5),
              1e-15);
  EXPECT_EQ(wave.Evaluate({0.125, 0.3, 0.7}).w, -1.0);
}

// A placed deformation (eq. 10): inside its box, D is the box's D carried by
// the placement's linear part at M^-1 u; outside, nothing moves or is cut; the
// forward map is inverted in the parent box too.
TEST(Deformation, PlacedDeformationsEvaluateInTheirOwnBox) {
  Deformation d = Make(DeformationKind::kTwist, 1.5, 0.1);
  d.parent_from_box =
      Placement::FromRegion({{0, 0, 0}, {1, 1, 1}}, {0, 0, 30}, 0.5, {0.25, 0, 0}).object_from_box;
  ASSERT_TRUE(d.Placed());
  const glm::dmat4 box_from_parent = glm::inverse(d.parent_from_box);
  const glm::dvec3 inside(0.8, 0.55, 0.7), outside(0.1, 0.5, 0.5);
  const glm::dvec3 b(box_from_parent * glm::dvec4(inside, 1.0));
  ASSERT_TRUE(glm::all(glm::greaterThan(b, glm::dvec3(0))) &&
              glm::all(glm::lessThan(b, glm::dvec3(1))));
  const glm::dvec3 expected = glm::dmat3(d.parent_from_box) * glm::dvec3(d.EvaluateInBox(b));
  EXPECT_NEAR(glm::length(glm::dvec3(d.Evaluate(inside)) - expected), 0.0, 1e-15);
  EXPECT_GT(glm::length(expected), 1e-3);
  EXPECT_EQ(d.Evaluate(outside), glm::dvec4(0, 0, 0, -1));
  const glm::dvec3 q = d.Forward(inside);
  EXPECT_NEAR(glm::length(q + glm::dvec3(d.Evaluate(q)) - inside), 0.0, 1e-12);
  // A sum of two placed deformations: each acts only in its own box.
  Deformation clip = Make(DeformationKind::kClip, 0.5, 0.0);
  clip.parent_from_box =
      Placement::FromRegion({{0, 0, 0}, {1, 1, 1}}, {0, 0, 0}, 1.0, {-0.5, 0, 0}).object_from_box;
  const DeformationSum sum{{d, clip}};
  EXPECT_GT(sum.Evaluate({0.2, 0.5, 0.9}).w, 0.0);  // the clip's box (x < 0.5), above 0.5
  EXPECT_LE(sum.Evaluate({0.8, 0.5, 0.9}).w, 0.0);  // beside it: not cut
  EXPECT_EQ(sum.Evaluate({0.2, 0.5, 0.9}).x, 0.0);  // the twist's box is x > 0.5
}

TEST(Deformation, BadParametersAreClearErrors) {
  EXPECT_THROW(Make(DeformationKind::kTwist, NAN, 0.3), InputError);
  EXPECT_THROW(Make(DeformationKind::kPull, 0.5, INFINITY), InputError);
  EXPECT_THROW(Make(DeformationKind::kKnife, 0.0, 0.5), InputError);
  EXPECT_THROW(Make(DeformationKind::kBend, 4.0, 0), InputError);
  EXPECT_THROW(DeformationKindFromName("peel2"), InputError);
  EXPECT_THROW(Placement::FromRegion({{0, 0, 0}, {1, 1, 1}}, {0, 0, 0}, 0.0), InputError);
  EXPECT_THROW(Placement::FromRegion({{0, 0, 0}, {1, NAN, 1}}), InputError);
  EXPECT_THROW(DeformationSum{}.Check(), InputError);
}

}  // namespace
}  // namespace core
