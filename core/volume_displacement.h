// Discontinuous displacement maps for volumes (Correa, Silver, Chen 2006,
// "Discontinuous Displacement Mapping for Volume Graphics"): the CPU side.
//
// A map stores the INVERSE displacement D (eq. 2-3): a point p' of the
// displaced space shows the object at p = p' + D(p'). Where p' has no
// pre-image (a cut opened the space), the cut mask alpha is 0 and D holds a
// continuous pseudo-inverse (sec. 4.1), so that trilinear filtering of D near
// the cut never mixes in an arbitrary value; samples with alpha < 0.5 are
// transparent and colour is modulated by alpha (sec. 4.2).
//
// Frames: a map lives on its own unit cube [0,1]^3 ("map space", u). It is
// placed into the volume's texture space [0,1]^3 (p) by an affine M
// (eq. 10): p = p' + A D(M^-1 p'), A the linear part of M; outside its cube a
// map is the identity (D = 0, alpha = 1). D is in map-space units.
// Several placed maps compose in one pass (eq. 9): p = G1(G2(p')), the LAST
// map of a list applied first, alphas multiplied.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"

namespace core {

// An inverse displacement map sampled at texel centres (i + 0.5) / n of its
// unit cube; d = D in map units, alpha = cut mask in [0, 1].
struct DisplacementMap {
  glm::ivec3 dims{0};
  std::vector<glm::vec4> texels;  // (D.x, D.y, D.z, alpha), x fastest

  size_t Index(int x, int y, int z) const {
    return (static_cast<size_t>(z) * dims.y + y) * dims.x + x;
  }
  const glm::vec4& at(int x, int y, int z) const { return texels[Index(x, y, z)]; }
  glm::vec4& at(int x, int y, int z) { return texels[Index(x, y, z)]; }
  // Largest |D| component: the scale of the [-1, 1] normalisation (sec. 4).
  float MaxAbsDisplacement() const;
};

// The procedural inverse maps of sec. 5-7, each on the unit cube. Each
// returns (D, alpha) at a map-space point u, alpha 1 or 0 (sharp; smoothing
// happens on the grid), D continuous everywhere (the pseudo-inverse where
// alpha = 0).
enum class Effect { kPeel, kSlices, kSeam, kPull, kWave, kClip, kCutaway, kWedge };
inline constexpr EnumName<Effect> kEffectNames[] = {
    {Effect::kPeel, "peel"},       {Effect::kSlices, "slices"}, {Effect::kSeam, "seam"},
    {Effect::kPull, "pull"},       {Effect::kWave, "wave"},     {Effect::kClip, "clip"},
    {Effect::kCutaway, "cutaway"}, {Effect::kWedge, "wedge"},
};
static_assert(EnumNamesUnique(kEffectNames));
std::string_view EffectName(Effect effect);
Effect ParseEffect(std::string_view name);  // InputError on an unknown name

struct EffectOptions {
  Effect effect = Effect::kPeel;
  // Peel (Fig. 1, 4): the slab z in [top - thickness, top], x > hinge_x is
  // rotated by angle_deg about the line (hinge_x, *, top) along y, up and
  // over; 180 flips it onto the surface with its underside facing up.
  double peel_top = 0.5;        // map units; room above it for the flipped layer
  double peel_thickness = 0.1;  // map units
  double peel_hinge_x = 0.5;    // map units
  double peel_angle_deg =
      160;  // degrees; 180 lays the layer flat ON the surface, a fold D cannot hold continuously
  // Periodic slicing (Fig. 6): slabs along x of width period - gap in the
  // object are spread to one per period, leaving gaps (cuts) of width gap.
  double slices_period = 0.25;  // map units
  double slices_gap = 0.06;     // map units, < period
  // Seam opening (Fig. 7): the halves x < 0.5 and x > 0.5 above seam_z are
  // pushed apart by a shift growing linearly to seam_width at z = 1.
  double seam_z = 0.3;      // map units, in [0, 1)
  double seam_width = 0.2;  // map units, full opening at the top
  // Gaussian pull (eq. 8): D = (0, 0, -z g(r)), r the distance from the line
  // x = y = 0.5 and g a Gaussian of width pull_sigma shifted and rescaled to
  // be 1 at r = 0 and 0 at r >= 0.5 (the XY faces' midpoints), so that
  // "sigma is chosen so that the displacement becomes 0 at the XY boundaries".
  double pull_sigma = 0.15;  // map units
  // Wave: D = (0, 0, amplitude sin(2 pi frequency x)), continuous, no cut.
  double wave_amplitude = 0.05;  // map units
  double wave_frequency = 2;     // periods across the map
  // Cut-aways (core/deformation.h's clip, cutaway, wedge: the same cuts a
  // mesh takes): nothing moves (D = 0), material is removed.
  double clip_height = 0.5;     // clip: above this z is removed, map units
  double cutaway_corner = 0.5;  // cutaway: the corner x, y, z > this is removed, map units
  double wedge_angle_deg = 90;  // wedge: opening about x = y = 0.5, centred on +x, (0, 180]
  double wedge_bottom = 0;      // wedge: it reaches from this z to the top, map units

  void Check() const;  // InputError on NaN/Inf or out-of-range values
  bool operator==(const EffectOptions&) const = default;
};

// (D, alpha) of the effect at map-space point u, exact (double).
glm::dvec4 EvaluateEffect(const EffectOptions& options, const glm::dvec3& u);
// Where the effect sends an object point (the forward map F, for tests and
// proxy bounds): F(p) with p' = F(p) satisfying p' + D(p') = p where alpha = 1.
glm::dvec3 ForwardEffect(const EffectOptions& options, const glm::dvec3& p);

// The effect sampled at texel centres of a dims grid. Where alpha = 0 the
// analytic pseudo-inverse is used when the effect has one (slices, seam);
// the peel's is the harmonic fill of FillPseudoInverse. `smooth_alpha_passes`
// binomial [1 2 1]/4 passes along each axis soften the mask for the normal
// blending of eq. 7 (the 0.5 contour stays at the cut). `fill_iterations`:
// FillPseudoInverse's (fewer: a rougher fill, for a preview while a
// parameter moves).
DisplacementMap SampleEffect(const EffectOptions& options, const glm::ivec3& dims,
                             int smooth_alpha_passes = 1, int fill_iterations = 200);

// Sec. 4.1: the continuous pseudo-inverse where no pre-image exists. Texels
// with `valid` false take the harmonic (Laplace) fill of D from the valid
// ones: Jacobi iterations from a nearest-valid start. Keeps valid texels.
void FillPseudoInverse(DisplacementMap& map, const std::vector<bool>& valid, int iterations = 200);

// ---- storage (sec. 4, 8): 8/16-bit normalised with scale and bias, or float ----
// Each texel is stored as D / scale in [-1, 1] mapped to [0, 1] (x 0.5 + 0.5)
// and alpha in [0, 1], as UNORM of `bits` bits; 32 bits stores floats as they
// are. Dequantize returns what a GL texture of that format gives back.
struct StoredDisplacementMap {
  glm::ivec3 dims{0};
  int bits = 16;                // 8, 16 or 32
  float scale = 1;              // D = (2 stored - 1) * scale for 8/16 bits
  std::vector<uint16_t> unorm;  // 4 per texel, for 8/16 bits (8-bit values fit)
  std::vector<float> floats;    // 4 per texel, for 32 bits
};
StoredDisplacementMap StoreDisplacementMap(const DisplacementMap& map, int bits);

DisplacementMap DequantizeDisplacementMap(const StoredDisplacementMap& stored);

// ---- evaluation (the CPU reference of the pass's shader) ----
// GL_LINEAR / CLAMP_TO_EDGE trilinear sample of a map at map-space u.
glm::dvec4 SampleMap(const DisplacementMap& map, const glm::dvec3& u);

// An axis-aligned box (lo..hi; empty when lo > hi on an axis).
struct Box3 {
  glm::dvec3 lo{0.0}, hi{1.0};
};

struct PlacedMap {
  const DisplacementMap* map = nullptr;
  glm::dmat4 placement{1.0};  // M: map space -> volume texture space (eq. 10)
  // Map space where the map is read; the identity elsewhere. The unit cube,
  // or ActiveBox of the stored map to mirror the volume pass exactly.
  Box3 active;
};
struct DisplacedSample {
  glm::dvec3 p{0.0};         // object (volume texture) point to sample
  double alpha = 1;          // product of the maps' masks
  glm::dmat3 jacobian{1.0};  // d p / d p' = product of (I + A J_D M^-1): for eq. 6 and 10
};
// p' -> p through every placed map (eq. 9, 10), the last map applied first.
// The Jacobian uses central differences of each map's trilinear field with
// step `fd_step` (map units; 0.5 texel is natural).
DisplacedSample Displace(const std::vector<PlacedMap>& maps, const glm::dvec3& p_prime,
                         bool with_jacobian = false);

// Per-texel derivatives of a map (sec. 4.3.1, "precomputed per voxel"):
// J_D = dD/du (column k = dD/du_k) and the mask's gradient dalpha/du, by
// central differences of the texels (one-sided at the faces), map units. The
// volume pass uploads them as three textures so a sample's normal costs three
// filtered fetches per map instead of six.
struct MapDerivatives {
  std::vector<glm::mat3> jacobian;        // J_D per texel
  std::vector<glm::vec3> alpha_gradient;  // grad alpha per texel
};
MapDerivatives ComputeMapDerivatives(const DisplacementMap& map);

// The axis-aligned box (volume texture space) holding every p' whose p lies
// in `object_box`: the proxy geometry of sec. 4.2 ("the bounding box of the
// object grown by the displacements"), found by pushing the object box's
// points through each map's forward extent: object box  U  placed map cubes.
// Always contains object_box.
Box3 ProxyBox(const Box3& object_box, const std::vector<PlacedMap>& maps);

// The part of a stored map's unit cube where it is not the identity: the
// texels whose stored (D, alpha) differ from the stored (0, 0, 0, 1), grown
// by two texels (one for the trilinear footprint, one for the central
// differences of ComputeMapDerivatives) and clipped to [0, 1]^3. Outside it
// the map (and its derivatives) read as the identity up to the storage's
// rounding of 0 (16 bits: 1.5e-5 scale), so the volume pass skips the fetch
// there. A map that is the identity everywhere gives an empty box (lo > hi).
Box3 ActiveBox(const StoredDisplacementMap& stored);

// A stored map's ActiveBox (texel-exact) in bricks of brick_texels^3
// texels (the last on an axis may be smaller), each classified by what a
// single map does to every DVR sample in it (render::VolumePass splits
// slices by them): kIdentity, every texel its samples and their derivatives
// read is the stored identity (two texels of margin, as ActiveBox); kCut,
// every texel its samples filter has alpha < 0.45 (so the sample's alpha
// < 0.5: transparent, sec. 4.2); kDisplaced, anything else. Outside the
// bricks the map is the identity. 8-bit maps have no kIdentity bricks: their
// stored zero reads as 0.4 % of the scale, which the displaced shader applies
// inside ActiveBox.
enum class MapBrickKind : uint8_t { kIdentity, kCut, kDisplaced };
struct MapBricks {
  glm::ivec3 dims{0};  // the map's texels
  int brick_texels = 0;
  glm::ivec3 lo{0}, hi{0};          // texels [lo, hi): ActiveBox's
  glm::ivec3 grid{0};               // bricks per axis; 0 when the map is the identity
  std::vector<MapBrickKind> kinds;  // x fastest
  // Map-space coordinate of brick boundary b (0..grid) along axis.
  double Edge(int axis, int b) const;
};
MapBricks ClassifyMapBricks(const StoredDisplacementMap& stored, int brick_texels);

}  // namespace core
