// The slicing core (Kautz-Seidel 2001, sec. 3): planar slices through a box
// -- a displacement volume, a depth-object cube, a volume's bounds -- in three
// families, ordered for compositing. Written once; every slicing pass
// (displacement, depth objects, visual hulls, volumes) uses it, on the CPU
// side here and through shaders/cores/slicing_core.glsl on the GPU side.
//
// Box space: the box is [0,1]^3 in its own coordinates, mapped to the world by
// the affine `world_from_box`. Box coordinates double as 3D texture
// coordinates of the sliced volume; for a displacement volume, box x/y are the
// base surface's (u, v) and box z is the height, so a fragment's ramp value
// h_alpha is simply its interpolated box z (sec. 3.2: the alpha ramp).
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/enum_names.h"

namespace render {

enum class SliceFamily {
  kSurfaceAligned,  // planes box z = const (direction a: parallel to the base surface)
  kOrthogonal,  // planes box k = const, k the axis whose world normal is most parallel to the view
  kScreen,      // planes parallel to the view plane (camera z = const)
};

enum class SliceOrder { kFrontToBack, kBackToFront };

inline constexpr core::EnumName<SliceFamily> kSliceFamilyNames[] = {
    {SliceFamily::kSurfaceAligned, "surface"},
    {SliceFamily::kOrthogonal, "orthogonal"},
    {SliceFamily::kScreen, "screen"},
    {SliceFamily::kSurfaceAligned, "surface-aligned"},  // alias
};
static_assert(core::EnumNamesUnique(kSliceFamilyNames));
// "surface" (or "surface-aligned"), "orthogonal", "screen" (InputError otherwise).
SliceFamily SliceFamilyFromName(const std::string& name);
std::string SliceFamilyName(SliceFamily family);

struct SliceBox {
  glm::mat4 world_from_box{1.0f};  // affine, non-singular
};

// How the viewer sees the box.
struct SliceView {
  glm::mat4 cam_from_world{1.0f};  // OpenCV convention: z forward
  bool orthographic = false;       // view direction = camera +z everywhere
};

struct SlicingOptions {
  SliceFamily family = SliceFamily::kOrthogonal;
  SliceOrder order = SliceOrder::kFrontToBack;
  // Number of slices (>= 1). Slice k of n sits at the centre of its cell:
  // box coordinate (k + 0.5) / n along the slicing axis (screen: along camera z
  // between the box's nearest and farthest corner), so no slice lies on a face
  // and the spacing is uniform.
  int count = 64;
  // Screen family only: also emit the full-size slice (the whole box's screen
  // rectangle, box coordinates reaching outside [0,1]^3), which the paper
  // draws with a zero-alpha texture border; kept to measure its extra fill.
  bool full_size_screen_slices = false;

  void Check() const;
};

struct Slice {
  // Convex polygon, counter-clockwise seen from the front (the viewer's side),
  // 3..6 vertices for exact slices, 4 for orthogonal/surface-aligned and full-size ones.
  std::vector<glm::vec3> p_in_box;
  // The plane: dot(normal_in_box, p) = offset_in_box for every vertex.
  float offset_in_box = 0;
};

struct SliceStack {
  SliceFamily family = SliceFamily::kOrthogonal;
  int axis = 2;  // box axis for surface-aligned / orthogonal slices, -1 for screen
  glm::vec3 normal_in_box{0, 0, 1};  // plane normal in box coordinates (not unit for screen slices)
  float spacing_in_box =
      0;  // distance between planes along the axis, box units (orthogonal / surface)
  float spacing_world = 0;    // distance between neighbouring planes in world units
  std::vector<Slice> slices;  // in the requested order
};

// The orthogonal family's axis: the box axis whose (world-space) plane normal
// is most parallel to the direction from the eye to the box centre. Ties go to
// the lowest axis index, so the choice is deterministic.
int ChooseOrthogonalAxis(const SliceBox& box, const SliceView& view);

// All slices of one frame.
SliceStack MakeSlices(const SliceBox& box, const SliceView& view, const SlicingOptions& options);

// Exact intersection of the plane dot(n, p) = d with the unit box [0,1]^3, as
// a convex polygon counter-clockwise around +n (empty if it misses the box or
// only touches it in fewer than 3 points).
std::vector<glm::vec3> ClipPlaneToUnitBox(glm::vec3 n, float d);

// Sutherland-Hodgman against one half-space: the part of the convex polygon
// with dot(n, p) <= d, same orientation (empty if fewer than 3 vertices stay).
// Cuts slices of a triangular displacement volume (box x + y <= 1) to the face.
std::vector<glm::vec3> ClipPolygonToHalfSpace(const std::vector<glm::vec3>& polygon, glm::vec3 n,
                                              float d);

// The polygon as a fan around its vertex mean: {mean, v0, v1, ..., v_{n-1},
// v0}. Fanned from its first vertex (SliceBuffer) it covers a convex polygon
// also when some vertices lie on the edge between their neighbours, where a
// fan from v0 would give zero-area triangles of either orientation.
std::vector<glm::vec3> CentroidFan(const std::vector<glm::vec3>& polygon);

// ---- a slice partitioned by an axis-aligned kd-tree (the volume pass's map bricks) ----
// Node i is a leaf (axis < 0) with `label`, or splits at `value` along
// `axis`: points with coordinate < value go to node `lo`, those > value to
// `hi`, those on the plane to `hi` if ties_hi, else to `lo`. nodes[0] is the
// root.
struct BoxTree {
  struct Node {
    int axis = -1;
    double value = 0;
    int lo = -1, hi = -1;
    int label = 0;
    bool ties_hi = false;
  };
  std::vector<Node> nodes;
  int Leaves() const;
  // The label of the leaf holding p.
  int LabelAt(const glm::dvec3& p) const;
};
// A grid of labelled cells (x fastest; cell (i, j, k) spans edges[0][i] ..
// edges[0][i + 1] along x, and so on; labels in 0..15) as a BoxTree: outside
// the bounding box of the cells labelled other than `background`, one
// background leaf per side; inside it, cells merged into boxes of one label
// by greedy splits (each split the plane that leaves the least volume in
// mixed children).
BoxTree BoxTreeOfGrid(const glm::ivec3& grid, const std::vector<uint8_t>& labels,
                      const std::array<std::vector<double>, 3>& edges, int background);
struct LabelledPolygon {
  std::vector<glm::dvec3> polygon;
  int label = 0;
};
// A convex polygon split by the tree's planes into convex parts, one per leaf
// it crosses (the whole polygon, untouched, when it meets one leaf). Cut
// vertices lie exactly on their plane and are shared bit for bit, and a cut
// ending on another part's edge puts its vertex into that part too, so the
// parts meet without T-junctions (GL's rules are watertight only across
// edges with identical end points): rasterised, every pixel centre of the
// polygon is covered by exactly one part. Draw split parts as CentroidFan.
// Vertices within `on_plane` of a plane count as on it (no sliver parts).
std::vector<LabelledPolygon> PartitionPolygon(const std::vector<glm::dvec3>& polygon,
                                              const BoxTree& tree, double on_plane = 1e-9);

// The box [lo, hi] as a BoxTree of its six planes: `inside` for the box (a
// point on a face counts as inside), `outside` around it (one leaf per plane).
BoxTree BoxTreeOfBox(const glm::dvec3& lo, const glm::dvec3& hi, int inside, int outside);
// Slices (box coordinates) split by `tree`, which lives in its own frame
// (tree_from_box: box coordinates to it): Split gives the parts back in box
// coordinates, ready for SliceBuffer, which fans each polygon from its first
// vertex: the slice untouched when it meets one leaf, else each part as a
// CentroidFan (a part can hold its neighbours' cut ends on its edges).
// Vertices within `on_plane` (tree units) of a plane count as on it.
struct SlicePart {
  std::vector<glm::vec3> p_in_box;
  int label = 0;
};
struct SliceSplitter {
  SliceSplitter(BoxTree tree, const glm::dmat4& tree_from_box, double on_plane);
  std::vector<SlicePart> Split(const std::vector<glm::vec3>& p_in_box) const;

  BoxTree tree;
  glm::dmat4 tree_from_box, box_from_tree;
  double on_plane;
};

// Area of a planar polygon (any orientation), in the units of its vertices.
float PolygonArea(const std::vector<glm::vec3>& polygon);

// ---- slice counts (sec. 3.4) ----
// Count giving at most `spacing_world` between planes along the axis.
int SliceCountForSpacing(float extent_world, float spacing_world);
// Directions b and c need count_a * edge_length / max_displacement slices to
// sample the displacement as densely as direction a does (sec. 3.4: edge 2,
// displacement 0.5 -> 4x the slices).
int OrthogonalSliceCount(int count_surface_aligned, float edge_length, float max_displacement);
// Screen-space: one slice per pixel of the box's projected extent, i.e. the
// length in pixels of the box's longest projected edge-to-corner diagonal.
int ScreenSliceCount(const SliceBox& box, const SliceView& view, const glm::mat4& clip_from_cam,
                     int viewport_width, int viewport_height);

}  // namespace render
