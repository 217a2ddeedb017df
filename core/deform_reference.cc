#include "core/deform_reference.h"

#include <algorithm>
#include <cmath>

namespace core {

DeformReference::DeformReference(const MeshDistance& mesh, const DeformationSum& deformation,
                                 const Placement& placement, CutMode cut, double thickness)
    : mesh_(mesh),
      deformation_(deformation),
      placement_(placement),
      cut_(cut),
      thickness_(thickness) {
  deformation_.Check();
  placement_.Check();
  pieces_ = deformation_.Pieces();
  Box3d bounds = placement_.ObjectBounds();
  scale_ = glm::length(bounds.size());
  // L: the largest spectral norm of I + J (object units) and |grad A| over a
  // 64^3 sampling of the box, per piece, times 1.25 for what falls between
  // samples (the deformations here are smooth at that scale; the knife's
  // kink only lowers |J|). Spectral norm <= Frobenius norm. The flap's
  // mask bounds its piece in every cut mode, so its gradient always counts.
  const glm::dmat3 linear = placement_.Linear(), inverse = glm::inverse(linear);
  double worst = 1.0;
  const int n = 64;
  for (int piece = 0; piece < pieces_; ++piece)
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          glm::dvec3 u = (glm::dvec3(i, j, k) + 0.5) / double(n);
          glm::dmat3 jw =
              glm::dmat3(1.0) + linear * deformation_.JacobianPiece(u, piece, 1e-6) * inverse;
          double frob = 0.0;
          for (int c = 0; c < 3; ++c) frob += glm::dot(jw[c], jw[c]);
          worst = std::max(worst, std::sqrt(frob));
          if (piece == 1 || cut_ == CutMode::kSolid || cut_ == CutMode::kThick) {
            glm::dvec3 g;
            for (int a = 0; a < 3; ++a) {
              glm::dvec3 e(0.0);
              e[a] = 1e-6;
              g[a] = (deformation_.EvaluatePiece(u + e, piece).w -
                      deformation_.EvaluatePiece(u - e, piece).w) /
                     2e-6;
            }
            worst = std::max(worst, glm::length(glm::transpose(inverse) * g));
          }
        }
  lipschitz_ = 1.25 * worst;
}

double DeformReference::Body(double sdf) const {
  return cut_ == CutMode::kThick ? std::abs(sdf + 0.5 * thickness_) - 0.5 * thickness_ : sdf;
}

double DeformReference::PieceField(const glm::dvec3& p, int piece) const {
  glm::dvec4 w = DeformObjectPointPiece(deformation_, placement_, p, piece);
  double body = Body(mesh_.SignedDistance(glm::dvec3(w)));
  if (piece == 1 || cut_ == CutMode::kSolid || cut_ == CutMode::kThick) return std::max(body, w.w);
  return body;
}

int DeformReference::ActivePiece(const glm::dvec3& p) const {
  return pieces_ == 2 && PieceField(p, 1) < PieceField(p, 0) ? 1 : 0;
}

double DeformReference::Field(const glm::dvec3& p) const {
  double f = PieceField(p, 0);
  return pieces_ == 2 ? std::min(f, PieceField(p, 1)) : f;
}

glm::dvec3 DeformReference::Gradient(const glm::dvec3& p, int piece, bool alpha) const {
  const double h = 1e-6 * scale_;
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 e(0.0);
    e[a] = h;
    const glm::dvec4 wp = DeformObjectPointPiece(deformation_, placement_, p + e, piece);
    const glm::dvec4 wm = DeformObjectPointPiece(deformation_, placement_, p - e, piece);
    g[a] = alpha ? wp.w - wm.w
                 : Body(mesh_.SignedDistance(glm::dvec3(wp))) -
                       Body(mesh_.SignedDistance(glm::dvec3(wm)));
  }
  return g / (2 * h);
}

DeformReferenceHit DeformReference::Trace(const glm::dvec3& origin, const glm::dvec3& dir,
                                          double t_min, double t_max) const {
  DeformReferenceHit result;
  const double eps = 1e-6 * scale_;  // surface tolerance (object units)
  double t = t_min;
  bool hollow = cut_ == CutMode::kHollow;
  for (int step = 0; step < 100000 && t <= t_max; ++step) {
    glm::dvec3 p = origin + t * dir;
    double f = Field(p);
    result.steps = step + 1;
    // Hollow shells are hit from either side: trace |F|.
    double distance = hollow ? std::abs(f) : f;
    if (distance < eps) {
      const int piece = ActivePiece(p);
      glm::dvec4 w = DeformObjectPointPiece(deformation_, placement_, p, piece);
      if (hollow && piece == 0 && w.w > 0) {
        // Rejected (sec. 5.1.1): step through the surface and go on.
        double t_start = t;
        while (t <= t_max && std::abs(Field(origin + t * dir)) < 4 * eps) t += eps;
        t = std::max(t, t_start + eps);
        continue;
      }
      result.hit = true;
      result.t = t;
      result.p = p;
      double body = Body(mesh_.SignedDistance(glm::dvec3(w)));
      // A cut face: the cut's term is the active one (eq. 6); the flap's
      // mask in every mode.
      result.cut_face =
          (piece == 1 || cut_ == CutMode::kSolid || cut_ == CutMode::kThick) && w.w > body;
      result.normal = glm::normalize(Gradient(p, piece, result.cut_face));
      // Entering = the field falls along the ray.
      result.entering = !hollow || Field(origin + (t + 2 * eps) * dir) <= f;
      return result;
    }
    t += std::max(distance / lipschitz_, 0.5 * eps);
  }
  return result;
}

}  // namespace core
