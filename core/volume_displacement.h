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

#include "core/deformation.h"

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

// The deformations of core/deformation.h (one vocabulary for meshes and
// volumes: kDeformationTable) as maps. A map holds one deformation in its own
// unit cube; its placement (Deformation::parent_from_box) becomes the
// PlacedMap's, so several deformations compose by eq. 9.
//
// (D, alpha) at map-space point u, exact (double): D = the deformation's
// inverse displacement (its own box, placement not applied), alpha 0 where
// its cut alpha A > 0 (material removed) and 1 elsewhere (sharp; smoothing
// happens on the grid). A peel's flap has no continuous D around it in one
// map (the mesh pass joins two pieces instead: core/deformation.h "Pieces"),
// so a volume's peel also removes the space above the flap's top hinge
// (z > 1 - T) outside the turned flap, and D is the pseudo-inverse fill
// there (FillPseudoInverse): the flap is surrounded by cut space, as in
// Correa 2006 Fig. 1, 4.
glm::dvec4 EvaluateVolumeMap(const Deformation& deformation, const glm::dvec3& u);

// Where a deformation's map lies in its box (box units): the box grown to
// hold where the deformation moves material (Correa 2006 sec. 4: displaced
// material outside the volume's box must still be drawn), so a twist's
// turned corners, the slices' and the knife's outer parts, a pull's or a
// wave's lifted top are not clipped. A peel's reaches up to z = 1.5 so that
// the turned flap (up to 0.5 + T above its hinge at 1 - T) stays inside the
// map, surrounded by removed space (a mesh's flap is clipped at its box's
// top instead). Growth is capped at kMaxMapGrowth box units each side
// (slices whose gap nearly fills the period would otherwise move material
// arbitrarily far); material beyond the cap is clipped.
inline constexpr double kMaxMapGrowth = 2.0;
Box3d VolumeMapBox(const Deformation& deformation);
// The same as an affine map: texel centres of the map's unit cube are at box
// point BoxFromMap * u.
glm::dmat4 BoxFromMap(const Deformation& deformation);
// The map's placement in the parent (PlacedMap::placement, eq. 10's M):
// deformation.parent_from_box * BoxFromMap(deformation).
glm::dmat4 VolumeMapPlacement(const Deformation& deformation);

// The grid a `size` map of `deformation` needs: `size` texels per box unit
// along each axis its map box spans (VolumeMapBox; a peel's 1.5 times
// `size` along z), at most kMaxMapTexels (or `size`); thin (at most 4
// texels) along axes the deformation does not vary on (Table 2: the peel and
// slicing maps are 128 x 128 x 1).
inline constexpr int kMaxMapTexels = 512;
glm::ivec3 VolumeMapDims(const Deformation& deformation, int size);

// The deformation sampled at texel centres of a dims grid. Where alpha = 0
// the deformation's own continuous pseudo-inverse is kept (slices, seam,
// knife); the peel's is the harmonic fill of FillPseudoInverse. `smooth_alpha_passes`
// binomial [1 2 1]/4 passes along each axis soften the mask for the normal
// blending of eq. 7 (the 0.5 contour stays at the cut). `fill_iterations`:
// FillPseudoInverse's (fewer: a rougher fill, for a preview while a
// parameter moves). The map spans BoxFromMap (D in map units); the
// placement is not applied (VolumeMapPlacement is the PlacedMap's).
DisplacementMap SampleDeformationMap(const Deformation& deformation, const glm::ivec3& dims,
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
