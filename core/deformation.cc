#include "core/deformation.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"

namespace core {
namespace {

constexpr glm::dvec2 kAxis{0.5, 0.5};  // twist and pull axis in (x, y), box units
// The flap's D is defined everywhere but used only where its mask is near
// or below 0 (the mask is 1-Lipschitz in box units): displacement bounds
// (and so the distance field's extent) count those nodes only.
constexpr double kFlapMargin = 0.05;

// Twist weight: 1 inside radius r0, smooth to 0 at the inscribed radius 0.5
// (so the twist vanishes on the four side faces), times z (0 on the bottom).
double TwistAngle(const Deformation& d, double r, double z) {
  double r0 = std::min(d.width, 0.5);
  double s = r <= r0 ? 1.0 : r >= 0.5 ? 0.0 : (0.5 - r) / (0.5 - r0);
  s = s * s * (3 - 2 * s);
  return d.amount * std::clamp(z, 0.0, 1.0) * s;
}

glm::dvec2 Rotate(const glm::dvec2& v, double a) {
  double c = std::cos(a), s = std::sin(a);
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}

// Knife opening width at height z: 0 below the cut, growing linearly to
// `amount` at the top face.
double KnifeWidth(const Deformation& d, double z) {
  double depth = std::max(d.width, 1e-9);
  return d.amount * std::clamp((z - (1.0 - depth)) / depth, 0.0, 1.0);
}

// Peel (Correa 2007 Fig. 1b, 4): the flap x >= 0.5, 1 - 2T <= z <= 1 - T
// turns by `angle` about the hinge line x = 0.5, z = 1 - T (lifting +x up).
constexpr double kPeelHinge = 0.5;
double PeelTop(const Deformation& d) { return 1.0 - d.width; }
// Signed distance-like alpha of the flap's slab (> 0 inside, box units).
// Its three bounding planes (each affine in u, > 0 on the slab's side); the
// slab's alpha is their minimum.
glm::dvec3 PeelSlabPlanes(const Deformation& d, const glm::dvec3& u) {
  const double top = PeelTop(d);
  return {u.x - kPeelHinge, u.z - (top - d.width), top - u.z};
}
double PeelSlab(const Deformation& d, const glm::dvec3& u) {
  const glm::dvec3 planes = PeelSlabPlanes(d, u);
  return std::min({planes.x, planes.y, planes.z});
}
// Rotation of (x, z) about the hinge by a (positive a lifts +x towards +z).
glm::dvec3 PeelRotate(const Deformation& d, const glm::dvec3& u, double a) {
  const glm::dvec2 v = Rotate(glm::dvec2(u.x - kPeelHinge, u.z - PeelTop(d)), a);
  return {kPeelHinge + v.x, u.y, PeelTop(d) + v.y};
}

// Pull profile (Correa 2006 eq. 8): a Gaussian of width sigma in the
// distance r from the axis, shifted and rescaled to be 1 at r = 0 and 0 at
// r >= 0.5, so "the displacement becomes 0 at the XY boundaries".
double PullProfile(double sigma, double r) {
  const double s2 = 2 * sigma * sigma;
  const double edge = std::exp(-0.25 / s2);
  return std::max(0.0, (std::exp(-r * r / s2) - edge) / (1 - edge));
}

// Slices (Correa 2006 Fig. 6): the object's slabs of thickness
// period - gap along x are spread to one per period; slab 0 (at x = 0)
// keeps its place. The inverse shift at x, continuous: in a gap it ramps
// from the slab before's shift to the next one's (the pseudo-inverse).
double SlicesShift(const Deformation& d, double x) {
  const double period = d.width, gap = d.amount;
  const double k = std::floor(x / period);
  return -k * gap - std::max(0.0, x - k * period - (period - gap));
}
// > 0 in a gap (distance to its faces), <= 0 in a slab: 1-Lipschitz.
double SlicesAlpha(const Deformation& d, double x) {
  const double period = d.width, gap = d.amount;
  const double c = period - 0.5 * gap;  // gap centre within a period
  const double k = std::round((x - c) / period);
  return 0.5 * gap - std::abs(x - (c + k * period));
}

bool InUnitBox(const glm::dvec3& u) {
  return u.x >= 0 && u.x <= 1 && u.y >= 0 && u.y <= 1 && u.z >= 0 && u.z <= 1;
}

}  // namespace

const DeformationInfo& DeformationInfoOf(DeformationKind kind) {
  for (const DeformationInfo& info : kDeformationTable) {
    if (info.kind == kind) return info;
  }
  ThrowInputError("DeformationInfoOf", "unknown deformation kind {}", static_cast<int>(kind));
}

Deformation Deformation::Default(DeformationKind kind) {
  const DeformationInfo& info = DeformationInfoOf(kind);
  Deformation d;
  d.kind = kind;
  d.amount = info.amount;
  d.width = info.width;
  return d;
}

DeformationKind DeformationKindFromName(const std::string& name) {
  return EnumFromName(kDeformationKindNames, name, "DeformationKindFromName", "deformation");
}

std::string DeformationKindName(DeformationKind kind) {
  return std::string(EnumToName(kDeformationKindNames, kind));
}

CutMode CutModeFromName(const std::string& name) {
  return EnumFromName(kCutModeNames, name, "CutModeFromName", "cut");
}

std::string CutModeName(CutMode mode) { return std::string(EnumToName(kCutModeNames, mode)); }

void Deformation::Check() const {
  if (!std::isfinite(amount) || !std::isfinite(width)) {
    ThrowInputError("Deformation", "{}: amount {} and width {} must be finite",
                    DeformationKindName(kind), amount, width);
  }
  switch (kind) {
    case DeformationKind::kTwist:
      if (std::abs(amount) > 8 * M_PI || width < 0 || width > 0.5) {
        ThrowInputError("Deformation",
                        "twist: |angle| {} must be <= 8 pi and radius {} in [0, 0.5]", amount,
                        width);
      }
      break;
    case DeformationKind::kBend:
      if (std::abs(amount) > M_PI)
        ThrowInputError("Deformation", "bend: |angle| {} must be <= pi", amount);
      break;
    case DeformationKind::kPull:
      if (std::abs(amount) > 1 || !(width > 1e-3) || width > 1) {
        ThrowInputError("Deformation",
                        "pull: |amplitude| {} must be <= 1 and width {} in (0.001, 1]", amount,
                        width);
      }
      break;
    case DeformationKind::kKnife:
      if (!(amount > 0) || amount > 0.5 || !(width > 0) || width > 1) {
        ThrowInputError("Deformation",
                        "knife: opening {} must be in (0, 0.5] and depth {} in (0, 1]", amount,
                        width);
      }
      break;
    case DeformationKind::kPeel:
      if (amount < 0 || amount > M_PI || !(width > 0) || width > 0.5) {
        ThrowInputError("Deformation",
                        "peel: angle {} must be in [0, pi] and thickness {} in (0, 0.5]", amount,
                        width);
      }
      break;
    case DeformationKind::kClip:
    case DeformationKind::kCutaway:
      if (amount < 0 || amount > 1) {
        ThrowInputError("Deformation", "{}: position {} must be in [0, 1] (box units)",
                        DeformationKindName(kind), amount);
      }
      break;
    case DeformationKind::kWedge:
      if (!(amount > 0) || amount > M_PI || width < 0 || width > 1) {
        ThrowInputError("Deformation", "wedge: angle {} must be in (0, pi] and bottom {} in [0, 1]",
                        amount, width);
      }
      break;
    case DeformationKind::kSlices:
      if (!(width > 0) || width > 1 || amount < 0 || amount >= width) {
        ThrowInputError("Deformation",
                        "slices: period {} must be in (0, 1] and gap {} in [0, period)", width,
                        amount);
      }
      break;
    case DeformationKind::kSeam:
      if (!(amount > 0) || amount > 0.5 || !(width > 0) || width > 1) {
        ThrowInputError("Deformation",
                        "seam: opening {} must be in (0, 0.5] and depth {} in (0, 1]", amount,
                        width);
      }
      break;
    case DeformationKind::kWave:
      if (std::abs(amount) > 0.5 || width < 0.02 || width > 4) {
        ThrowInputError("Deformation",
                        "wave: |amplitude| {} must be <= 0.5 and wavelength {} in [0.02, 4]",
                        amount, width);
      }
      break;
  }
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(parent_from_box[c][r]))
        ThrowInputError("Deformation", "{}: the placement is not finite",
                        DeformationKindName(kind));
    }
  if (!(std::abs(glm::determinant(glm::dmat3(parent_from_box))) > 1e-12))
    ThrowInputError("Deformation", "{}: the placement is singular", DeformationKindName(kind));
}

double CutAwayAlpha(DeformationKind kind, double amount, double width, const glm::dvec3& u) {
  switch (kind) {
    case DeformationKind::kClip:
      return u.z - amount;
    case DeformationKind::kCutaway:
      return std::min({u.x - amount, u.y - amount, u.z - amount});
    case DeformationKind::kWedge: {
      // Its two faces are the half-planes through the axis at +-amount/2
      // from +x; unit normals, so each term is a distance.
      const double h = 0.5 * amount;
      const glm::dvec2 v = glm::dvec2(u) - kAxis;
      return std::min({std::sin(h) * v.x + std::cos(h) * v.y, std::sin(h) * v.x - std::cos(h) * v.y,
                       u.z - width});
    }
    default:
      break;
  }
  ThrowInputError("CutAwayAlpha", "{} is not a cut-away", DeformationKindName(kind));
}

glm::dvec4 Deformation::EvaluateInBox(const glm::dvec3& u) const {
  switch (kind) {
    case DeformationKind::kTwist: {
      // Forward: rotate (x, y) about the axis by alpha(r, z); r is preserved,
      // so the inverse rotates by -alpha(r, z) (Correa 2007 sec. 4: D = -D_f).
      glm::dvec2 v = glm::dvec2(u) - kAxis;
      glm::dvec2 w = Rotate(v, -TwistAngle(*this, glm::length(v), u.z));
      return {w - v, 0.0, -1.0};
    }
    case DeformationKind::kBend: {
      // Barr 1984: the line x = 0.5 bends into an arc of radius rho = 1/k
      // about the centre (0.5 + rho, z = 0), k = amount; z beyond the bent
      // part continues rigidly. Inverse: the point's angle about the centre,
      // clamped to [0, amount], unrolls it.
      if (std::abs(amount) < 1e-12) return {0, 0, 0, -1};
      double rho = 1.0 / amount;
      glm::dvec2 v(u.x - 0.5 - rho, u.z);
      double theta = std::atan2(u.z * (rho > 0 ? 1 : -1), (0.5 + rho - u.x) * (rho > 0 ? 1 : -1));
      double tc = std::clamp(theta, std::min(0.0, amount), std::max(0.0, amount));
      double c = std::cos(tc), s = std::sin(tc);
      glm::dvec2 v0(v.x * c - v.y * s, v.x * s + v.y * c);  // rotate by -tc (see Forward)
      double x = 0.5 + rho + v0.x, z = rho * tc + v0.y;
      return {x - u.x, 0.0, z - u.z, -1.0};
    }
    case DeformationKind::kPull: {
      // Correa 2006 eq. 8 (and the narrow pull of Correa 2007 Fig. 3): along
      // +z, scaled by z and the Gaussian profile of the distance from the axis.
      const double r = glm::length(glm::dvec2(u) - kAxis);
      return {0.0, 0.0, -amount * std::clamp(u.z, 0.0, 1.0) * PullProfile(width, r), -1.0};
    }
    case DeformationKind::kSlices:
      return {SlicesShift(*this, u.x), 0.0, 0.0, SlicesAlpha(*this, u.x)};
    case DeformationKind::kWave:
      return {0.0, 0.0, amount * std::sin(2 * M_PI * u.x / width), -1.0};
    case DeformationKind::kSeam:  // Correa 2006 Fig. 7's seam is the knife's map
    case DeformationKind::kKnife: {
      // Forward: the halves x < 0.5 and x > 0.5 move apart by w(z)/2 each.
      // Inverse: a point in the gap maps onto the plane x = 0.5 (D stays
      // continuous); A = w/2 - |x - 0.5| is > 0 in the gap, also below the
      // blade (w = 0: A <= 0), so A is Lipschitz everywhere (1 in x, the
      // blade's taper in z) and A / Lipschitz(A) bounds the distance to the
      // gap: the empty-space skip of sec. 6.2 (a constant -1 below the blade
      // made A jump by up to 1 in one texel and the bound useless).
      double half = 0.5 * KnifeWidth(*this, u.z);
      double dx = -std::clamp(u.x - 0.5, -half, half);
      double alpha = half - std::abs(u.x - 0.5);
      return {dx, 0.0, 0.0, alpha};
    }
    case DeformationKind::kPeel: {
      // Inverse: where the turned flap came from (the flap wins where it
      // overlaps the slab it left); the vacated slab is cut (A > 0, its
      // faces the cut faces; A is 1-Lipschitz in box units). D jumps at the
      // flap's faces: the peel is a cut, the flap's own faces are crossings.
      if (amount <= 0) return {0, 0, 0, -1};
      const glm::dvec3 q = PeelRotate(*this, u, -amount);
      if (PeelSlab(*this, q) >= 0) return {q - u, -1.0};
      return {0.0, 0.0, 0.0, std::max(PeelSlab(*this, u), -1.0)};
    }
    case DeformationKind::kClip:
    case DeformationKind::kCutaway:
    case DeformationKind::kWedge:
      return {0.0, 0.0, 0.0, CutAwayAlpha(kind, amount, width, u)};
  }
  return {0, 0, 0, -1};
}

glm::dvec4 Deformation::EvaluatePieceInBox(const glm::dvec3& u, int piece) const {
  if (kind != DeformationKind::kPeel) return EvaluateInBox(u);
  if (piece == 0) return {0.0, 0.0, 0.0, std::max(PeelSlab(*this, u), -1.0)};  // the slab left
  // The flap: where its rigid rotation came from, everywhere (continuous);
  // the mask is > 0 outside the turned slab.
  const glm::dvec3 q = PeelRotate(*this, u, -amount);
  return {q - u, std::max(-PeelSlab(*this, q), -1.0)};
}

glm::dvec3 Deformation::ForwardInBox(const glm::dvec3& u) const {
  switch (kind) {
    case DeformationKind::kTwist: {
      glm::dvec2 v = glm::dvec2(u) - kAxis;
      return {kAxis + Rotate(v, TwistAngle(*this, glm::length(v), u.z)), u.z};
    }
    case DeformationKind::kBend: {
      if (std::abs(amount) < 1e-12) return u;
      double rho = 1.0 / amount;
      double tc = std::clamp(u.z / rho, std::min(0.0, amount), std::max(0.0, amount));
      glm::dvec2 v0(u.x - 0.5 - rho, u.z - rho * tc);
      double c = std::cos(tc), s = std::sin(tc);
      glm::dvec2 v(v0.x * c + v0.y * s, -v0.x * s + v0.y * c);  // rotate by +tc
      return {0.5 + rho + v.x, u.y, v.y};
    }
    case DeformationKind::kSlices: {
      // Object slab k = floor(x / (period - gap)) moves to start at k period.
      const double k = std::floor(u.x / (width - amount));
      return {u.x + k * amount, u.y, u.z};
    }
    case DeformationKind::kSeam:
    case DeformationKind::kKnife: {
      double half = 0.5 * KnifeWidth(*this, u.z);
      double side = u.x > 0.5 ? 1.0 : u.x < 0.5 ? -1.0 : 0.0;
      return {u.x + side * half, u.y, u.z};
    }
    case DeformationKind::kPeel:
      return PeelSlab(*this, u) >= 0 ? PeelRotate(*this, u, amount) : u;
    case DeformationKind::kClip:
    case DeformationKind::kCutaway:
    case DeformationKind::kWedge:
      return u;
    case DeformationKind::kPull:
    case DeformationKind::kWave:
      break;
  }
  ThrowInputError("Deformation::Forward", "{} has no closed-form forward map",
                  DeformationKindName(kind));
}

namespace {

// (D, A) of a placed deformation at u of its parent box: its own box's
// (D, A) at M^-1 u with D carried by M's linear part (eq. 10) and A scaled
// to parent units (exact for a uniform scale), at least -1; outside its box the identity
// with alpha `outside_alpha`.
template <typename F>
glm::dvec4 InParent(const glm::dmat4& parent_from_box, const glm::dvec3& u, double outside_alpha,
                    F evaluate) {
  const glm::dvec3 b(glm::inverse(parent_from_box) * glm::dvec4(u, 1.0));
  if (!InUnitBox(b)) return {0.0, 0.0, 0.0, outside_alpha};
  const glm::dmat3 linear(parent_from_box);
  const glm::dvec4 e = evaluate(b);
  const double scale = std::cbrt(std::abs(glm::determinant(linear)));
  // Clamped at -1 as every alpha is (a peel's flap mask below -1 would read
  // as "no peel term" in DeformationSum::EvaluatePiece).
  return {linear * glm::dvec3(e), std::max(e.w * scale, -1.0)};
}

}  // namespace

glm::dvec4 Deformation::Evaluate(const glm::dvec3& u) const {
  if (!Placed()) return EvaluateInBox(u);
  return InParent(parent_from_box, u, -1.0, [&](const glm::dvec3& b) { return EvaluateInBox(b); });
}

glm::dvec4 Deformation::EvaluatePiece(const glm::dvec3& u, int piece) const {
  if (!Placed()) return EvaluatePieceInBox(u, piece);
  // Piece 1 outside the box: no flap there (mask > 0).
  return InParent(parent_from_box, u, piece == 1 && kind == DeformationKind::kPeel ? 1.0 : -1.0,
                  [&](const glm::dvec3& b) { return EvaluatePieceInBox(b, piece); });
}

glm::dvec3 Deformation::Forward(const glm::dvec3& u) const {
  if (!Placed()) return ForwardInBox(u);
  const glm::dvec3 b(glm::inverse(parent_from_box) * glm::dvec4(u, 1.0));
  if (!InUnitBox(b)) return u;
  return glm::dvec3(parent_from_box * glm::dvec4(ForwardInBox(b), 1.0));
}

void DeformationSum::Check() const {
  if (terms.empty()) ThrowInputError("DeformationSum", "no deformation given");
  for (const Deformation& d : terms) d.Check();
}

glm::dvec4 DeformationSum::Evaluate(const glm::dvec3& u) const {
  glm::dvec4 sum(0.0, 0.0, 0.0, -1.0);
  for (const Deformation& d : terms) {
    glm::dvec4 e = d.Evaluate(u);
    sum = glm::dvec4(glm::dvec3(sum) + glm::dvec3(e), std::max(sum.w, e.w));
  }
  return sum;
}

glm::dmat3 DeformationSum::Jacobian(const glm::dvec3& u, double h) const {
  glm::dmat3 j(0.0);
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 e(0.0);
    e[a] = h;
    j[a] = (glm::dvec3(Evaluate(u + e)) - glm::dvec3(Evaluate(u - e))) /
           (2 * h);  // column a = dD/du_a
  }
  return j;
}

int DeformationSum::Pieces() const {
  return std::any_of(terms.begin(), terms.end(),
                     [](const Deformation& d) { return d.kind == DeformationKind::kPeel; })
             ? 2
             : 1;
}

glm::dvec4 DeformationSum::EvaluatePiece(const glm::dvec3& u, int piece) const {
  glm::dvec4 sum(0.0, 0.0, 0.0, piece == 0 ? -1.0 : -1e300);
  for (const Deformation& d : terms) {
    const glm::dvec4 e = d.EvaluatePiece(u, piece);
    sum = glm::dvec4(glm::dvec3(sum) + glm::dvec3(e), sum.w);
    if (piece == 0 || d.kind == DeformationKind::kPeel) sum.w = std::max(sum.w, e.w);
  }
  if (sum.w < -1.0) sum.w = 1.0;  // piece 1 without a peel: no flap anywhere
  return sum;
}

glm::dmat3 DeformationSum::JacobianPiece(const glm::dvec3& u, int piece, double h) const {
  glm::dmat3 j(0.0);
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 e(0.0);
    e[a] = h;
    j[a] = (glm::dvec3(EvaluatePiece(u + e, piece)) - glm::dvec3(EvaluatePiece(u - e, piece))) /
           (2 * h);
  }
  return j;
}

glm::dvec4 DeformationSum::AlphaComponents(const glm::dvec3& u, int piece) const {
  const Deformation* peel = nullptr;
  int peels = 0;
  double others = -1.0;  // piece 0: the other terms' cut alphas (their max, at least -1)
  for (const Deformation& d : terms) {
    if (d.kind == DeformationKind::kPeel) {
      peel = &d;
      ++peels;
    } else if (piece == 0) {
      others = std::max(others, d.EvaluatePiece(u, 0).w);
    }
  }
  const double sign = AlphaComponentSign(piece);
  if (peels != 1 || peel->Placed()) return glm::dvec4(sign * EvaluatePiece(u, piece).w);
  if (piece == 0) return {PeelSlabPlanes(*peel, u), others};
  // The flap's mask -slab(q): q is a rotation of u, so each plane stays affine.
  return {PeelSlabPlanes(*peel, PeelRotate(*peel, u, -peel->amount)), -1e30};
}

double DeformationSum::AlphaFromComponents(const glm::dvec4& c, int piece) {
  return std::max(AlphaComponentSign(piece) * std::max(c.w, std::min({c.x, c.y, c.z})), -1.0);
}

bool DeformationSum::HasCut() const {
  return std::any_of(terms.begin(), terms.end(), [](const Deformation& d) { return d.HasCut(); });
}

Placement Placement::FromRegion(const Box3d& region, const glm::dvec3& rotation_deg, double scale,
                                const glm::dvec3& translation) {
  glm::dvec3 centre = 0.5 * (region.lo + region.hi);
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), centre + translation);
  m = glm::rotate(m, glm::radians(rotation_deg.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(rotation_deg.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotation_deg.x), glm::dvec3(1, 0, 0));
  m = glm::scale(m, glm::dvec3(scale) * region.size());
  m = glm::translate(m, glm::dvec3(-0.5));
  Placement placement{m};
  placement.Check();
  return placement;
}

void Placement::Check() const {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(object_from_box[c][r]))
        ThrowInputError("Placement", "the placement is not finite");
    }
  double det = glm::determinant(Linear());
  if (!(std::abs(det) > 1e-18))
    ThrowInputError("Placement", "the placement is singular (determinant {})", det);
}

Box3d Placement::ObjectBounds() const {
  Box3d box{glm::dvec3(1e300), glm::dvec3(-1e300)};
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 p(object_from_box * glm::dvec4(c & 1, (c >> 1) & 1, (c >> 2) & 1, 1.0));
    box.lo = glm::min(box.lo, p);
    box.hi = glm::max(box.hi, p);
  }
  return box;
}

glm::dvec4 DeformObjectPoint(const DeformationSum& deformation, const Placement& placement,
                             const glm::dvec3& p_deformed) {
  glm::dvec3 u(placement.BoxFromObject() * glm::dvec4(p_deformed, 1.0));
  if (glm::any(glm::lessThan(u, glm::dvec3(0.0))) ||
      glm::any(glm::greaterThan(u, glm::dvec3(1.0)))) {
    return {p_deformed, -1.0};
  }
  glm::dvec4 e = deformation.Evaluate(u);
  return {p_deformed + placement.Linear() * glm::dvec3(e), e.w};
}

glm::dvec4 DeformObjectPointPiece(const DeformationSum& deformation, const Placement& placement,
                                  const glm::dvec3& p_deformed, int piece) {
  glm::dvec3 u(placement.BoxFromObject() * glm::dvec4(p_deformed, 1.0));
  if (glm::any(glm::lessThan(u, glm::dvec3(0.0))) ||
      glm::any(glm::greaterThan(u, glm::dvec3(1.0)))) {
    return {p_deformed, piece == 0 ? -1.0 : 1.0};
  }
  glm::dvec4 e = deformation.EvaluatePiece(u, piece);
  return {p_deformed + placement.Linear() * glm::dvec3(e), e.w};
}

DeformationTexture SampleDeformation(const DeformationSum& deformation, int resolution) {
  deformation.Check();
  if (resolution < 2 || resolution > 512) {
    ThrowInputError("SampleDeformation", "resolution {} outside 2..512", resolution);
  }
  DeformationTexture texture;
  texture.resolution = resolution;
  texture.pieces = deformation.Pieces();
  texture.rgba.resize(static_cast<size_t>(texture.pieces) * resolution * resolution * resolution *
                      4);
  // With a flap, the pieces' alpha components on the same nodes (exact cut-face normals).
  const bool components = texture.pieces == 2;
  if (components) texture.alpha_components.resize(texture.rgba.size());
  size_t n = 0;
  for (int piece = 0; piece < texture.pieces; ++piece)
    for (int k = 0; k < resolution; ++k)
      for (int j = 0; j < resolution; ++j)
        for (int i = 0; i < resolution; ++i, n += 4) {
          const glm::dvec3 u = glm::dvec3(i, j, k) / double(resolution - 1);
          const glm::dvec4 e = deformation.EvaluatePiece(u, piece);
          if (piece == 0 || e.w <= kFlapMargin) {
            texture.max_displacement_box =
                std::max(texture.max_displacement_box, glm::length(glm::dvec3(e)));
          }
          for (int c = 0; c < 4; ++c) texture.rgba[n + c] = static_cast<float>(e[c]);
          if (!components) continue;
          const glm::dvec4 a = deformation.AlphaComponents(u, piece);
          for (int c = 0; c < 4; ++c) texture.alpha_components[n + c] = static_cast<float>(a[c]);
        }
  return texture;
}

double MaxObjectDisplacement(const DeformationSum& deformation, const Placement& placement,
                             int resolution) {
  double best = 0.0;
  glm::dmat3 linear = placement.Linear();
  for (int piece = 0; piece < deformation.Pieces(); ++piece)
    for (int k = 0; k < resolution; ++k)
      for (int j = 0; j < resolution; ++j)
        for (int i = 0; i < resolution; ++i) {
          glm::dvec4 e =
              deformation.EvaluatePiece(glm::dvec3(i, j, k) / double(resolution - 1), piece);
          if (piece == 1 && e.w > kFlapMargin) continue;  // no flap near: D unused
          best = std::max(best, glm::length(linear * glm::dvec3(e)));
        }
  return best;
}

}  // namespace core
