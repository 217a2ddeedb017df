#include "render/cores/slicing.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/check.h"
#include "core/error.h"
#include "core/summed_volume.h"

namespace render {

SliceFamily SliceFamilyFromName(const std::string& name) {
  return core::EnumFromName(kSliceFamilyNames, name, "SliceFamilyFromName", "slicing family");
}

std::string SliceFamilyName(SliceFamily family) {
  return std::string(core::EnumToName(kSliceFamilyNames, family));
}

void SlicingOptions::Check() const {
  // 16384 slices at 1 px each is already far beyond any viewport's depth extent.
  if (count < 1 || count > 16384) {
    core::ThrowInputError("SlicingOptions", "slice count {} outside 1..16384", count);
  }
}

namespace {

struct ViewFrame {
  glm::vec3 eye_world{0};         // perspective centre (unused for orthographic)
  glm::vec3 axis_world{0, 0, 1};  // camera +z in the world
};

ViewFrame FrameOf(const SliceView& view) {
  const glm::mat3 r(view.cam_from_world);
  const glm::vec3 t(view.cam_from_world[3]);
  ViewFrame f;
  f.axis_world = glm::transpose(r) * glm::vec3(0, 0, 1);
  f.eye_world = -(glm::transpose(r) * t);
  return f;
}

// Direction the viewer looks at the box (unit, world), robust for an eye at
// the box centre (falls back to the camera axis).
glm::vec3 ViewDirectionToBox(const SliceBox& box, const SliceView& view) {
  const ViewFrame f = FrameOf(view);
  if (view.orthographic) return f.axis_world;
  const glm::vec3 centre = glm::vec3(box.world_from_box * glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  const glm::vec3 d = centre - f.eye_world;
  const float len = glm::length(d);
  return len > 1e-12f ? d / len : f.axis_world;
}

// Gradient of box coordinate k with respect to world position.
glm::vec3 BoxAxisGradientWorld(const SliceBox& box, int k) {
  const glm::mat3 inv = glm::inverse(glm::mat3(box.world_from_box));
  return glm::vec3(inv[0][k], inv[1][k], inv[2][k]);  // row k of the inverse
}

glm::vec3 EyeInBox(const SliceBox& box, const SliceView& view) {
  return glm::vec3(glm::inverse(box.world_from_box) * glm::vec4(FrameOf(view).eye_world, 1.0f));
}

glm::vec3 DirectionInBox(const SliceBox& box, glm::vec3 d_world) {
  return glm::inverse(glm::mat3(box.world_from_box)) * d_world;
}

// A planar quad for axis-aligned slices, CCW around `toward_viewer`.
std::vector<glm::vec3> AxisQuad(int axis, float c, float sign_toward_viewer) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis
  std::vector<glm::vec3> quad(4, glm::vec3(c));
  const float corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 4; ++i) {
    quad[i][u] = corners[i][0];
    quad[i][v] = corners[i][1];
  }
  if (sign_toward_viewer < 0) std::reverse(quad.begin(), quad.end());
  return quad;
}

}  // namespace

int ChooseOrthogonalAxis(const SliceBox& box, const SliceView& view) {
  const glm::vec3 d = ViewDirectionToBox(box, view);
  int best = 0;
  float best_score = -1;
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 g = BoxAxisGradientWorld(box, k);
    const float len = glm::length(g);
    const float score = len > 0 ? std::abs(glm::dot(g / len, d)) : 0.0f;
    // Near-ties (1e-6) keep the lower axis, so the choice is deterministic.
    if (score > best_score + 1e-6f) {
      best_score = score;
      best = k;
    }
  }
  return best;
}

std::vector<glm::vec3> ClipPlaneToUnitBox(glm::vec3 n, float d) {
  std::vector<glm::vec3> points;
  if (!(glm::dot(n, n) > 0) || !std::isfinite(d)) return points;
  const glm::vec3 corner[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                            {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  auto add = [&](glm::vec3 p) {
    for (const auto& q : points) {
      if (glm::length(q - p) < 1e-6f) return;
    }
    points.push_back(p);
  };
  for (const auto& e : edges) {
    const glm::vec3 a = corner[e[0]], b = corner[e[1]];
    const float sa = glm::dot(n, a) - d, sb = glm::dot(n, b) - d;
    if (sa == 0) add(a);
    if (sb == 0) add(b);
    if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) add(a + (b - a) * (sa / (sa - sb)));
  }
  if (points.size() < 3) return {};
  glm::vec3 centre(0);
  for (const auto& p : points) centre += p;
  centre /= static_cast<float>(points.size());
  const glm::vec3 nn = glm::normalize(n);
  const glm::vec3 helper = std::abs(nn.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::vec3 u = glm::normalize(glm::cross(helper, nn));
  const glm::vec3 v = glm::cross(nn, u);
  std::sort(points.begin(), points.end(), [&](const glm::vec3& a, const glm::vec3& b) {
    return std::atan2(glm::dot(a - centre, v), glm::dot(a - centre, u)) <
           std::atan2(glm::dot(b - centre, v), glm::dot(b - centre, u));
  });
  return points;
}

std::vector<glm::vec3> ClipPolygonToHalfSpace(const std::vector<glm::vec3>& polygon, glm::vec3 n,
                                              float d) {
  std::vector<glm::vec3> out;
  const size_t count = polygon.size();
  for (size_t i = 0; i < count; ++i) {
    const glm::vec3 a = polygon[i], b = polygon[(i + 1) % count];
    const float sa = glm::dot(n, a) - d, sb = glm::dot(n, b) - d;
    if (sa <= 0) out.push_back(a);
    if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) out.push_back(a + (b - a) * (sa / (sa - sb)));
  }
  if (out.size() < 3) return {};
  return out;
}

BoxTree BoxTreeOfBox(const glm::dvec3& lo, const glm::dvec3& hi, int inside, int outside) {
  // The six planes in turn, each with the outside as a leaf and the rest
  // split further by the next plane.
  BoxTree tree;
  for (int plane = 0; plane < 6; ++plane) {
    const int axis = plane / 2;
    const bool upper = (plane % 2) == 1;
    const int node = static_cast<int>(tree.nodes.size());
    const int next = node + 2;  // the node after this one's outside leaf
    tree.nodes.push_back({.axis = axis,
                          .value = upper ? hi[axis] : lo[axis],
                          .lo = upper ? next : node + 1,
                          .hi = upper ? node + 1 : next,
                          .ties_hi = !upper});  // on the plane counts as inside
    tree.nodes.push_back({.label = outside});
  }
  tree.nodes.push_back({.label = inside});
  return tree;
}

SliceSplitter::SliceSplitter(BoxTree tree_in, const glm::dmat4& tree_from_box_in,
                             double on_plane_in)
    : tree(std::move(tree_in)),
      tree_from_box(tree_from_box_in),
      box_from_tree(glm::inverse(tree_from_box_in)),
      on_plane(on_plane_in) {}

std::vector<SlicePart> SliceSplitter::Split(const std::vector<glm::vec3>& p_in_box) const {
  std::vector<glm::dvec3> in_tree;
  in_tree.reserve(p_in_box.size());
  for (const glm::vec3& v : p_in_box) in_tree.emplace_back(tree_from_box * glm::dvec4(v, 1.0));
  std::vector<LabelledPolygon> parts = PartitionPolygon(in_tree, tree, on_plane);
  if (parts.size() == 1) return {{p_in_box, parts[0].label}};
  std::vector<SlicePart> out;
  out.reserve(parts.size());
  for (const LabelledPolygon& part : parts) {
    std::vector<glm::vec3> polygon;
    polygon.reserve(part.polygon.size());
    for (const glm::dvec3& u : part.polygon)
      polygon.emplace_back(box_from_tree * glm::dvec4(u, 1.0));
    out.push_back({CentroidFan(polygon), part.label});
  }
  return out;
}

int BoxTree::Leaves() const {
  int leaves = 0;
  for (const Node& n : nodes) leaves += n.axis < 0;
  return leaves;
}

int BoxTree::LabelAt(const glm::dvec3& p) const {
  int i = 0;
  while (nodes[i].axis >= 0) {
    const Node& n = nodes[i];
    const double x = p[n.axis];
    i = x < n.value || (x == n.value && !n.ties_hi) ? n.lo : n.hi;
  }
  return nodes[i].label;
}

BoxTree BoxTreeOfGrid(const glm::ivec3& grid, const std::vector<uint8_t>& labels,
                      const std::array<std::vector<double>, 3>& edges, int background) {
  constexpr int kLabels = 16;
  const size_t cells = static_cast<size_t>(grid.x) * grid.y * grid.z;
  IBR_CHECK_EQ(labels.size(), cells);
  for (int a = 0; a < 3; ++a) IBR_CHECK_EQ(edges[a].size(), static_cast<size_t>(grid[a]) + 1);
  IBR_CHECK(background >= 0 && background < kLabels);
  BoxTree tree;
  auto leaf = [&](int label) {
    tree.nodes.push_back({.label = label});
    return static_cast<int>(tree.nodes.size()) - 1;
  };
  auto split = [&](int axis, double value) {
    tree.nodes.push_back({.axis = axis, .value = value});
    return static_cast<int>(tree.nodes.size()) - 1;
  };
  // The bounding box of the foreground cells.
  glm::ivec3 lo = grid, hi(-1);
  for (int z = 0; z < grid.z; ++z)
    for (int y = 0; y < grid.y; ++y)
      for (int x = 0; x < grid.x; ++x) {
        const uint8_t l = labels[(static_cast<size_t>(z) * grid.y + y) * grid.x + x];
        IBR_CHECK(l < kLabels);
        if (l == background) continue;
        lo = glm::min(lo, glm::ivec3(x, y, z));
        hi = glm::max(hi, glm::ivec3(x, y, z) + 1);
      }
  if (hi.x < 0) {
    leaf(background);
    return tree;
  }
  // Per-label counts, for the labels that occur.
  std::vector<std::optional<core::SummedVolume>> counts(kLabels);
  for (int k = 0; k < kLabels; ++k) {
    if (std::find(labels.begin(), labels.end(), k) == labels.end()) continue;
    std::vector<uint8_t> is_k(labels.size());
    for (size_t i = 0; i < labels.size(); ++i) is_k[i] = labels[i] == k;
    counts[k].emplace(grid, is_k);
  }
  // The one label of cells [a, b) or -1 when mixed.
  auto uniform = [&](const glm::ivec3& a, const glm::ivec3& b) {
    const int volume = (b.x - a.x) * (b.y - a.y) * (b.z - a.z);
    for (int k = 0; k < kLabels; ++k) {
      if (!counts[k]) continue;
      const int n = counts[k]->Count(a, b);
      if (n == 0) continue;
      return n == volume ? k : -1;
    }
    return -1;
  };
  auto volume = [](const glm::ivec3& a, const glm::ivec3& b) {
    return static_cast<double>(b.x - a.x) * (b.y - a.y) * (b.z - a.z);
  };
  // Cells [a, b): a leaf, or the split leaving the least volume in mixed
  // children (ties: the more central plane).
  auto build = [&](auto&& self, glm::ivec3 a, glm::ivec3 b) -> int {
    if (const int l = uniform(a, b); l >= 0) return leaf(l);
    int best_axis = -1, best_at = 0;
    double best_cost = 1e300, best_offset = 1e300;
    for (int axis = 0; axis < 3; ++axis) {
      for (int c = a[axis] + 1; c < b[axis]; ++c) {
        glm::ivec3 left_hi = b, right_lo = a;
        left_hi[axis] = c;
        right_lo[axis] = c;
        const double cost = (uniform(a, left_hi) < 0 ? volume(a, left_hi) : 0) +
                            (uniform(right_lo, b) < 0 ? volume(right_lo, b) : 0);
        const double offset = std::abs(c - 0.5 * (a[axis] + b[axis])) / (b[axis] - a[axis]);
        if (cost < best_cost || (cost == best_cost && offset < best_offset)) {
          best_axis = axis, best_at = c, best_cost = cost, best_offset = offset;
        }
      }
    }
    IBR_CHECK(best_axis >= 0);  // a mixed range has two cells on some axis
    const int node = split(best_axis, edges[best_axis][best_at]);
    glm::ivec3 left_hi = b, right_lo = a;
    left_hi[best_axis] = best_at;
    right_lo[best_axis] = best_at;
    const int l = self(self, a, left_hi);
    const int r = self(self, right_lo, b);
    tree.nodes[node].lo = l;
    tree.nodes[node].hi = r;
    return node;
  };
  // Background on each side of the bounding box, then the grid inside it.
  int parent = -1;
  bool parent_lo = false;
  auto attach = [&](int child) {
    if (parent < 0) return;
    (parent_lo ? tree.nodes[parent].lo : tree.nodes[parent].hi) = child;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (const bool upper : {false, true}) {
      const int bound = upper ? hi[axis] : lo[axis];
      const int node = split(axis, edges[axis][bound]);
      attach(node);
      const int outside = leaf(background);
      (upper ? tree.nodes[node].hi : tree.nodes[node].lo) = outside;
      parent = node;
      parent_lo = upper;
    }
  }
  attach(build(build, lo, hi));
  return tree;
}

std::vector<LabelledPolygon> PartitionPolygon(const std::vector<glm::dvec3>& polygon,
                                              const BoxTree& tree, double on_plane) {
  struct Piece {
    std::vector<glm::dvec3> v;
    int node;
  };
  std::vector<Piece> pieces{{polygon, 0}};
  std::vector<size_t> pending{0};
  while (!pending.empty()) {
    const size_t i = pending.back();
    pending.pop_back();
    const BoxTree::Node node = tree.nodes[pieces[i].node];
    if (node.axis < 0) continue;
    // Moved out: the cut below inserts into every piece but this one, and
    // pieces[i] is replaced by its lower part.
    std::vector<glm::dvec3> v = std::move(pieces[i].v);
    const size_t n = v.size();
    // s > 0: the hi side.
    std::vector<double> s(n);
    bool any_lo = false, any_hi = false;
    for (size_t k = 0; k < n; ++k) {
      s[k] = v[k][node.axis] - node.value;
      if (std::abs(s[k]) <= on_plane) s[k] = 0;
      any_lo = any_lo || s[k] < 0;
      any_hi = any_hi || s[k] > 0;
    }
    if (!any_hi || !any_lo) {
      // One side, or on the plane (ties).
      pieces[i].node = any_hi || (!any_lo && node.ties_hi) ? node.hi : node.lo;
      pieces[i].v = std::move(v);
      pending.push_back(i);
      continue;
    }
    std::vector<glm::dvec3> lo, hi;
    for (size_t k = 0; k < n; ++k) {
      const glm::dvec3 a = v[k], b = v[(k + 1) % n];
      const double sa = s[k], sb = s[(k + 1) % n];
      if (sa <= 0) lo.push_back(a);
      if (sa >= 0) hi.push_back(a);
      if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) {
        glm::dvec3 c = a + (b - a) * (sa / (sa - sb));
        c[node.axis] = node.value;  // exactly on the plane
        lo.push_back(c);
        hi.push_back(c);
        // Any other part with the edge a-b gets c too.
        for (size_t p = 0; p < pieces.size(); ++p) {
          if (p == i) continue;
          std::vector<glm::dvec3>& q = pieces[p].v;
          for (size_t j = 0; j < q.size(); ++j) {
            const glm::dvec3& x = q[j];
            const glm::dvec3& y = q[(j + 1) % q.size()];
            if ((x == a && y == b) || (x == b && y == a)) {
              q.insert(q.begin() + static_cast<std::ptrdiff_t>(j + 1), c);
              break;
            }
          }
        }
      }
    }
    pieces[i] = {std::move(lo), node.lo};
    pending.push_back(i);
    pieces.push_back({std::move(hi), node.hi});
    pending.push_back(pieces.size() - 1);
  }
  std::vector<LabelledPolygon> parts;
  parts.reserve(pieces.size());
  for (Piece& p : pieces) parts.push_back({std::move(p.v), tree.nodes[p.node].label});
  return parts;
}

std::vector<glm::vec3> CentroidFan(const std::vector<glm::vec3>& polygon) {
  glm::vec3 mean(0.0f);
  for (const glm::vec3& v : polygon) mean += v;
  mean /= static_cast<float>(polygon.size());
  std::vector<glm::vec3> fan = {mean};
  fan.insert(fan.end(), polygon.begin(), polygon.end());
  fan.push_back(polygon.front());
  return fan;
}

float PolygonArea(const std::vector<glm::vec3>& polygon) {
  glm::vec3 twice_area(0);
  for (size_t i = 1; i + 1 < polygon.size(); ++i) {
    twice_area += glm::cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
  }
  return 0.5f * glm::length(twice_area);
}

SliceStack MakeSlices(const SliceBox& box, const SliceView& view, const SlicingOptions& options) {
  options.Check();
  IBR_CHECK(std::abs(glm::determinant(glm::mat3(box.world_from_box))) > 0);
  SliceStack stack;
  stack.family = options.family;
  const int n = options.count;
  const glm::vec3 d_world = ViewDirectionToBox(box, view);

  if (options.family != SliceFamily::kScreen) {
    const int axis =
        options.family == SliceFamily::kSurfaceAligned ? 2 : ChooseOrthogonalAxis(box, view);
    stack.axis = axis;
    stack.spacing_in_box = 1.0f / n;
    stack.spacing_world = stack.spacing_in_box / glm::length(BoxAxisGradientWorld(box, axis));
    // Order key: how far along the view a plane c is. Orthographic: c times the
    // view direction's sign along the axis. Perspective: |c - eye| (planes on
    // the eye's side first; valid for every ray, also with the eye inside).
    const glm::vec3 eye = EyeInBox(box, view);
    const float dir_k = DirectionInBox(box, d_world)[axis];
    std::vector<float> planes(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) planes[k] = (k + 0.5f) / n;
    auto key = [&](float c) {
      if (view.orthographic) return dir_k >= 0 ? c : -c;
      return std::abs(c - eye[axis]);
    };
    std::stable_sort(planes.begin(), planes.end(),
                     [&](float a, float b) { return key(a) < key(b); });
    if (options.order == SliceOrder::kBackToFront) std::reverse(planes.begin(), planes.end());
    // The viewer is on the side the view direction comes from.
    const float toward = dir_k >= 0 ? -1.0f : 1.0f;
    stack.normal_in_box = glm::vec3(0);
    stack.normal_in_box[axis] = toward;
    for (float c : planes) {
      const float sign = view.orthographic ? toward : (eye[axis] >= c ? 1.0f : -1.0f);
      stack.slices.push_back({AxisQuad(axis, c, sign), toward * c});
    }
    return stack;
  }

  // Screen-space: planes camera z = const. In box coordinates camera z is
  // dot(g, p) + g0 with g = row 2 of (cam_from_world * world_from_box).
  stack.axis = -1;
  const glm::mat4 cam_from_box = view.cam_from_world * box.world_from_box;
  const glm::vec3 g(cam_from_box[0][2], cam_from_box[1][2], cam_from_box[2][2]);
  const float g0 = cam_from_box[3][2];
  float zmin = INFINITY, zmax = -INFINITY;
  std::vector<glm::vec3> corners_cam;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    const glm::vec3 p = glm::vec3(cam_from_box * glm::vec4(c, 1.0f));
    corners_cam.push_back(p);
    zmin = std::min(zmin, p.z);
    zmax = std::max(zmax, p.z);
  }
  // Perspective: slices at or behind the eye can never be seen.
  if (!view.orthographic) zmin = std::max(zmin, 0.0f);
  const float range = std::max(zmax - zmin, 0.0f);
  stack.spacing_world = range / n;
  stack.normal_in_box = -g;  // toward the viewer: camera z decreases
  const glm::mat4 box_from_cam = glm::inverse(cam_from_box);
  // Full-size slices: the box's screen rectangle (orthographic: in camera x/y;
  // perspective: in x/z, y/z), placed at each plane's depth.
  glm::vec2 lo(INFINITY), hi(-INFINITY);
  for (const auto& p : corners_cam) {
    const glm::vec2 q = view.orthographic ? glm::vec2(p) : glm::vec2(p) / std::max(p.z, 1e-6f);
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  for (int k = 0; k < n; ++k) {
    const int i = options.order == SliceOrder::kFrontToBack ? k : n - 1 - k;
    const float z = zmin + (i + 0.5f) * range / n;
    Slice slice;
    slice.offset_in_box = -(z - g0);
    if (options.full_size_screen_slices) {
      const glm::vec2 rect[4] = {{lo.x, lo.y}, {lo.x, hi.y}, {hi.x, hi.y}, {hi.x, lo.y}};
      for (const auto& r : rect) {
        const glm::vec3 p_cam = view.orthographic ? glm::vec3(r, z) : glm::vec3(r * z, z);
        slice.p_in_box.push_back(glm::vec3(box_from_cam * glm::vec4(p_cam, 1.0f)));
      }
      // The rectangle is counter-clockwise around camera -z; a mirroring box
      // map flips that in box coordinates, where exact slices are CCW.
      if (glm::determinant(glm::mat3(cam_from_box)) < 0) {
        std::reverse(slice.p_in_box.begin(), slice.p_in_box.end());
      }
    } else {
      slice.p_in_box = ClipPlaneToUnitBox(-g, -(z - g0));
      if (slice.p_in_box.empty()) continue;  // the plane grazes a corner
    }
    stack.slices.push_back(std::move(slice));
  }
  return stack;
}

int SliceCountForSpacing(float extent_world, float spacing_world) {
  if (!(extent_world > 0) || !(spacing_world > 0) || !std::isfinite(extent_world / spacing_world)) {
    core::ThrowInputError("SliceCountForSpacing",
                          "extent {} / spacing {} must be positive and finite", extent_world,
                          spacing_world);
  }
  return std::clamp(static_cast<int>(std::ceil(extent_world / spacing_world)), 1, 16384);
}

int OrthogonalSliceCount(int count_surface_aligned, float edge_length, float max_displacement) {
  if (count_surface_aligned < 1 || !(edge_length > 0) || !(max_displacement > 0)) {
    core::ThrowInputError("OrthogonalSliceCount",
                          "need count >= 1, edge > 0, displacement > 0 "
                          "(got {}, {}, {})",
                          count_surface_aligned, edge_length, max_displacement);
  }
  const double count =
      std::ceil(static_cast<double>(count_surface_aligned) * edge_length / max_displacement);
  return static_cast<int>(std::clamp(count, 1.0, 16384.0));
}

int ScreenSliceCount(const SliceBox& box, const SliceView& view, const glm::mat4& clip_from_cam,
                     int viewport_width, int viewport_height) {
  const glm::mat4 clip_from_box = clip_from_cam * view.cam_from_world * box.world_from_box;
  glm::vec2 px[8];
  for (int i = 0; i < 8; ++i) {
    const glm::vec4 c = clip_from_box * glm::vec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0f);
    const float w = std::max(std::abs(c.w), 1e-6f);
    px[i] = glm::vec2(c.x / w * 0.5f * viewport_width, c.y / w * 0.5f * viewport_height);
  }
  float longest = 0;
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) longest = std::max(longest, glm::length(px[i] - px[j]));
  }
  return std::clamp(static_cast<int>(std::ceil(longest)), 1, 16384);
}

}  // namespace render
