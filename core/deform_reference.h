// An independent CPU reference of the deform pass, in double: sphere tracing
// (Hart 1996) of the same implicit with the exact mesh distance (CGAL, not
// the sampled field), the analytic deformation (not its texture) and the
// analytic cut alpha. The step |F| / L uses L >= max |grad F| (for
// sdf(T^-1 p), |grad| <= ||I + J_D||; for the cut term, |grad A|), so the
// first surface is never stepped over (up to the bound's sampling, below).
// Same conventions as render/passes/deform_pass.h: F > 0 empty. A sum with a
// peel is the union (min) of its two pieces' fields (core/deformation.h,
// "Pieces"): the rest (the cut mode's field) and the flap (bounded by its
// mask in every mode).
#pragma once

#include <glm/glm.hpp>

#include "core/deformation.h"
#include "core/distance_field.h"

namespace core {

struct DeformReferenceHit {
  bool hit = false;
  bool cut_face = false;   // the hit is on the cut's face (solid / thick cuts)
  bool entering = true;    // hollow: false = the inside of the shell (leaving the solid)
  double t = 0.0;          // along the ray from its origin
  glm::dvec3 p{0.0};       // deformed-space point
  glm::dvec3 normal{0.0};  // unit; eq. 5 on the mesh, grad A on a cut face
  int steps = 0;
};

class DeformReference {
 public:
  DeformReference(const MeshDistance& mesh, const DeformationSum& deformation,
                  const Placement& placement, CutMode cut, double thickness);
  // The implicit at deformed-space point p (ray-core sign: > 0 empty).
  double Field(const glm::dvec3& p) const;
  // Sphere traces p = origin + t dir (dir unit) for t in [t_min, t_max].
  DeformReferenceHit Trace(const glm::dvec3& origin, const glm::dvec3& dir, double t_min,
                           double t_max) const;
  double lipschitz() const { return lipschitz_; }

 private:
  double Body(double sdf) const;
  // One piece's field (piece 1: the flap, bounded by its mask).
  double PieceField(const glm::dvec3& p, int piece) const;
  // The piece whose field is the smaller at p (0 without a flap).
  int ActivePiece(const glm::dvec3& p) const;
  glm::dvec3 Gradient(const glm::dvec3& p, int piece, bool alpha) const;

  const MeshDistance& mesh_;
  const DeformationSum& deformation_;
  Placement placement_;
  CutMode cut_;
  double thickness_;
  double lipschitz_ = 1.0;
  double scale_ = 1.0;  // box diagonal, object units (tolerances)
  int pieces_ = 1;
};

}  // namespace core
