// Deformations as inverse displacement fields (Correa-Silver-Chen 2007,
// sec. 3-4): a point p' of deformed space shows the undeformed point
// p = p' + D(p') (eq. 1). D lives in a unit texture box u in [0, 1]^3; the
// placement maps it into object space (eq. 2: p = p' + M D(M^-1 p'), M's
// linear part applied to the displacement vector). Each deformation also
// carries a cut alpha A(u) (sec. 5): A > 0 inside the cut (material removed
// or opened), <= 0 elsewhere; -1 everywhere for continuous deformations.
//
// Which faces of the box each deformation vanishes on (the seam with the
// rasterised, undeformed mesh must not cross any other face):
//   twist  all faces but the top (z = 1)              (as the paper requires)
//   bend   the bottom face (z = 0)
//   pull   the bottom face (z = 0); the sides up to exp(-1/(8 w^2)) of the amplitude
//   knife  the bottom face (z = 0); the cut opens from the top face
//   peel   the bottom face (z = 0) for T < 0.5; the flap is a layer across
//          the whole box in y that turns about the hinge x = 0.5 (like the
//          knife, the region is placed with its y faces beyond the object)
//          and is clipped where it leaves the box through the top or x = 0
//   seam   as the knife (Correa 2006 Fig. 7's seam opening is the knife's map)
//   slices the face x = 0; slabs move towards +x and leave through x = 1, so
//          the box must enclose the object with room at +x
//   wave   no face (D.z = amount sin(2 pi x / width)): the box must enclose
//          the object
//   clip, cutaway, wedge  D = 0 everywhere; their cut reaches every face
//          but the bottom, so the box must enclose the object (the default
//          region does) or the cut stops at the box where the mesh is drawn
//
// Volumes sample the same functions into a displacement map
// (core/volume_displacement.h: alpha 0 where A > 0).
//
// Cut-aways (clip, cutaway, wedge) move nothing: material is removed where
// A > 0, A a signed distance in box units (1-Lipschitz, so the cut's skip
// bound holds). The same functions cut volumes (core/volume_displacement.h).
//
// Pieces. A peel's inverse displacement jumps at the turned flap's faces
// (two pre-images meet there), and a sampled D interpolated across the jump
// maps the texels of that band anywhere: ragged flap edges and specks. So a
// sum with a peel is two pieces, each with a continuous D, joined by a union
// of their fields: piece 0 (the rest) has D = 0 for the peel and its vacated
// slab as cut alpha; piece 1 (the flap) has the peel's rigid rotation D
// everywhere and as alpha the mask -slab(q) (> 0 outside the flap), which
// bounds the piece in every cut mode (its zero set is the flap's cut faces).
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <iterator>
#include <string>
#include <vector>

#include "core/distance_field.h"
#include "core/enum_names.h"

namespace core {

enum class DeformationKind {
  kTwist,
  kBend,
  kPull,
  kKnife,
  kPeel,
  kClip,
  kCutaway,
  kWedge,
  kSlices,
  kSeam,
  kWave
};
inline constexpr EnumName<DeformationKind> kDeformationKindNames[] = {
    {DeformationKind::kTwist, "twist"},     {DeformationKind::kBend, "bend"},
    {DeformationKind::kPull, "pull"},       {DeformationKind::kKnife, "knife"},
    {DeformationKind::kPeel, "peel"},       {DeformationKind::kClip, "clip"},
    {DeformationKind::kCutaway, "cutaway"}, {DeformationKind::kWedge, "wedge"},
    {DeformationKind::kSlices, "slices"},   {DeformationKind::kSeam, "seam"},
    {DeformationKind::kWave, "wave"},
};
static_assert(EnumNamesUnique(kDeformationKindNames));

// THE table of deformations: one vocabulary for meshes (Correa 2007, through
// the distance field) and volumes (Correa 2006, sampled into a displacement
// map). Every entry is an inverse displacement D plus a cut alpha A on the
// unit box u in [0, 1]^3, with two parameters, `amount` and `width`, in box
// units or radians; the defaults are what `ibr deform` and `ibr volume` use
// when a value is not given. docs/guide/deformations.md shows the same table.
struct DeformationInfo {
  DeformationKind kind;
  double amount, width;  // defaults
  const char* amount_meaning;
  const char* width_meaning;
};
inline constexpr DeformationInfo kDeformationTable[] = {
    {DeformationKind::kTwist, 2.0, 0.35, "angle at the top face (rad, |a| <= 8 pi)",
     "radius inside which the twist is rigid (box units, [0, 0.5])"},
    {DeformationKind::kBend, 0.8, 0.0, "bend angle over z in [0, 1] (rad, |a| <= pi)", "unused"},
    {DeformationKind::kPull, 0.5, 0.03, "pull amplitude along +z (box units, |a| <= 1)",
     "Gaussian width sigma (box units, (0.001, 1]); 0 at the side faces"},
    {DeformationKind::kKnife, 0.15, 0.6, "opening at the top face (box units, (0, 0.5])",
     "depth of the cut from the top face (box units, (0, 1])"},
    {DeformationKind::kPeel, 2.4, 0.15, "angle the flap turns by (rad, [0, pi])",
     "flap thickness T (box units, (0, 0.5]); flap 1-2T <= z <= 1-T, x >= 0.5"},
    {DeformationKind::kClip, 0.5, 0.0, "height above which is removed (box units, [0, 1])",
     "unused"},
    {DeformationKind::kCutaway, 0.5, 0.0,
     "low corner of the removed corner box on each axis (box units, [0, 1])", "unused"},
    {DeformationKind::kWedge, M_PI / 2, 0.0,
     "opening angle about x = y = 0.5, centred on +x (rad, (0, pi])",
     "bottom height of the wedge (box units, [0, 1])"},
    {DeformationKind::kSlices, 0.06, 0.25, "gap opened between slices (box units, [0, width))",
     "slicing period along x (box units, (0, 1])"},
    {DeformationKind::kSeam, 0.2, 0.7, "opening at the top face (box units, (0, 0.5])",
     "depth of the opening from the top face (box units, (0, 1])"},
    {DeformationKind::kWave, 0.05, 0.5, "amplitude along z (box units, |a| <= 0.5)",
     "wavelength along x (box units, [0.02, 4])"},
};
static_assert(std::size(kDeformationTable) == std::size(kDeformationKindNames));
const DeformationInfo& DeformationInfoOf(DeformationKind kind);

DeformationKind DeformationKindFromName(const std::string& name);  // InputError if unknown
std::string DeformationKindName(DeformationKind kind);

struct Deformation {
  DeformationKind kind = DeformationKind::kTwist;
  // What each parameter means per kind: kDeformationTable.
  double amount = 1.0;
  double width = 0.3;
  // Where this deformation's unit box sits in its parent box (a mesh's
  // deformation region, a volume's texture cube): parent = M(u), affine
  // (Correa 2006 eq. 10; composite maps, Fig. 5). Identity: the whole parent.
  // Outside its box a deformation is the identity with no cut.
  glm::dmat4 parent_from_box{1.0};

  // The kind with the table's default amount and width.
  static Deformation Default(DeformationKind kind);
  void Check() const;  // InputError on NaN/inf or out-of-range values
  bool operator==(const Deformation&) const = default;
  bool Placed() const { return parent_from_box != glm::dmat4(1.0); }
  // (D(u), A(u)): inverse displacement (parent box units) and cut alpha at u
  // of the parent box.
  glm::dvec4 Evaluate(const glm::dvec3& u) const;
  bool HasForward() const {
    return kind != DeformationKind::kPull && kind != DeformationKind::kWave;
  }
  // The forward map T(u) (T^-1(T(u)) = u) where it has a closed form.
  glm::dvec3 Forward(const glm::dvec3& u) const;
  bool HasCut() const {
    return kind == DeformationKind::kKnife || kind == DeformationKind::kPeel ||
           kind == DeformationKind::kSlices || kind == DeformationKind::kSeam || IsCutAway();
  }
  bool IsCutAway() const {
    return kind == DeformationKind::kClip || kind == DeformationKind::kCutaway ||
           kind == DeformationKind::kWedge;
  }
  // (D, A) of one piece (see "Pieces" above): piece 0 = the rest, piece 1 =
  // the peel's flap (A = its mask). Both continuous in u. Terms other than
  // the peel are the same in both pieces (Evaluate).
  glm::dvec4 EvaluatePiece(const glm::dvec3& u, int piece) const;
  // The same in the deformation's own box (no placement).
  glm::dvec4 EvaluateInBox(const glm::dvec3& u) const;
  glm::dvec4 EvaluatePieceInBox(const glm::dvec3& u, int piece) const;
  glm::dvec3 ForwardInBox(const glm::dvec3& u) const;
};

// A cut-away's alpha at u (box units, > 0 where material is removed): clip
// u.z - amount; cutaway min over axes of u - amount; wedge the minimum of the
// distances to its two half-planes and u.z - width. `kind` must be a cut-away.
double CutAwayAlpha(DeformationKind kind, double amount, double width, const glm::dvec3& u);

// How a cut alpha is rendered (sec. 5): no cut, hollow thin shell (hits in
// the cut discarded), solid (eq. 6: the cut reveals a new face), thick shell
// of thickness T (eq. 7).
enum class CutMode { kNone, kHollow, kSolid, kThick };
// "thick" is written "thick:T" where a cut is parsed (the caller splits T off).
inline constexpr EnumName<CutMode> kCutModeNames[] = {
    {CutMode::kNone, "none"},
    {CutMode::kHollow, "hollow"},
    {CutMode::kSolid, "solid"},
    {CutMode::kThick, "thick", "thick:T"},
};
static_assert(EnumNamesUnique(kCutModeNames));
// "none", "hollow", "solid", "thick" (InputError otherwise).
CutMode CutModeFromName(const std::string& name);
std::string CutModeName(CutMode mode);

// A sum of deformations (the paper's "addition of deformation textures"):
// D = sum of D_i, A = max of A_i.
struct DeformationSum {
  std::vector<Deformation> terms;
  bool operator==(const DeformationSum&) const = default;
  void Check() const;
  glm::dvec4 Evaluate(const glm::dvec3& u) const;
  // J_D(u) by central differences (step h in box units).
  glm::dmat3 Jacobian(const glm::dvec3& u, double h = 1e-5) const;
  bool HasCut() const;
  // Pieces (see above): 2 when a term is a peel, else 1 (piece 0 = Evaluate).
  int Pieces() const;
  // Piece 0: D = sum, A = max over terms of EvaluatePiece(u, 0). Piece 1:
  // D = sum of EvaluatePiece(u, 1), A = max over the peels' masks only (the
  // flap's domain; other terms' cuts apply to the rest).
  glm::dvec4 EvaluatePiece(const glm::dvec3& u, int piece) const;
  // J_D of one piece by central differences.
  glm::dmat3 JacobianPiece(const glm::dvec3& u, int piece, double h = 1e-5) const;
  // A piece's cut alpha as four smooth components c, for exact cut-face
  // normals: A = AlphaFromComponents(c, piece) = max(s max(c.w, min(c.x, c.y,
  // c.z)), -1), s = AlphaComponentSign(piece). A lone peel's slab is the
  // minimum of three planes; sampled and interpolated, that minimum is
  // rounded within a texel of the slab's edges and its gradient there blends
  // the faces' normals (by up to 64 degrees at 64^3), while each plane alone
  // (affine in u, the flap's too: q is a rotation of u) is interpolated
  // exactly. So with exactly one peel c.xyz are its planes (of u
  // for piece 0, of the flap's pre-image q for piece 1) and c.w the other
  // terms' alpha (piece 0; -1e30 for the flap); otherwise every component is
  // s A (no kink resolved: a sum of two peels, or none).
  glm::dvec4 AlphaComponents(const glm::dvec3& u, int piece) const;
  static double AlphaComponentSign(int piece) { return piece == 0 ? 1.0 : -1.0; }
  static double AlphaFromComponents(const glm::dvec4& c, int piece);
};

// Where the deformation box sits in object space: object = M(u), affine.
struct Placement {
  glm::dmat4 object_from_box{1.0};

  // The region box as given, then rotated about its centre by Euler angles
  // (degrees, x then y then z), scaled about its centre, then translated.
  static Placement FromRegion(const Box3d& region, const glm::dvec3& rotation_deg = glm::dvec3(0.0),
                              double scale = 1.0, const glm::dvec3& translation = glm::dvec3(0.0));
  glm::dmat4 BoxFromObject() const { return glm::inverse(object_from_box); }
  glm::dmat3 Linear() const { return glm::dmat3(object_from_box); }
  // Axis-aligned object-space bounds of the placed box.
  Box3d ObjectBounds() const;
  void Check() const;  // InputError when not finite or singular
};

// Eq. 2 in object space: the undeformed point p = p' + M D(M^-1 p') and the
// cut alpha at p' (-1 outside the box, where D = 0).
glm::dvec4 DeformObjectPoint(const DeformationSum& deformation, const Placement& placement,
                             const glm::dvec3& p_deformed);
// The same for one piece (DeformationSum::EvaluatePiece); outside the box
// piece 1's mask is +1 (no flap there).
glm::dvec4 DeformObjectPointPiece(const DeformationSum& deformation, const Placement& placement,
                                  const glm::dvec3& p_deformed, int piece);

// The deformation sampled on the nodes of a res^3 grid over the box
// (node (i, j, k) at u = (i, j, k) / (res - 1); as a 3D texture its texel
// centres are the nodes, lookup coordinate (u (res - 1) + 0.5) / res), RGBA:
// D in box units, A; one res^3 block per piece (DeformationSum::Pieces),
// piece 0 first.
struct DeformationTexture {
  int resolution = 0;
  int pieces = 1;
  std::vector<float> rgba;  // 4 floats per node, x fastest, pieces * res^3 nodes
  // DeformationSum::AlphaComponents on the same nodes and in the same layout;
  // sampled only when there are two pieces (a peel), else empty.
  std::vector<float> alpha_components;
  double max_displacement_box = 0.0;  // max |D| over the nodes, box units
};
DeformationTexture SampleDeformation(const DeformationSum& deformation, int resolution);

// Max |M D| over the nodes: how far the distance field must extend beyond the box.
double MaxObjectDisplacement(const DeformationSum& deformation, const Placement& placement,
                             int resolution);

}  // namespace core
