// Novel cameras for rendering image-based objects: turntable orbits around
// the object's box, and other datasets' cameras resized to an output size;
// and the one conversion between the view cameras here (ibr::ViewCamera),
// capture's rig views (capture::RigView, what capture::RenderView and
// DatasetWriter take) and render passes' ViewSetup.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "ibr/image_maps.h"
#include "render/passes/mesh_pass.h"
#include "scene/scene.h"

namespace ibr {

struct NamedView {
  std::string name;  // used for output file names
  ViewCamera view;
};

struct OrbitOptions {
  int count = 24;             // views around the full circle (>= 1)
  int size = 512;             // pixels, square
  glm::dvec3 up{0, 1, 0};     // turntable axis (OBJ meshes are y-up; capture's default)
  double elevation_deg = 20;  // camera height above the box centre's horizontal plane
  double fov_deg = 40;        // full field of view; the distance frames the box's bounding sphere
  // Azimuth span in degrees: 360 = the full circle (count views, none
  // repeated); less = `count` views from one end of the arc to the other,
  // centred on `towards`.
  double arc_deg = 360;
  // With an arc: the direction from the box centre towards the arc's middle
  // camera (only its part across `up` counts). Zero: the first axis across up.
  glm::dvec3 towards{0.0};
  void Check() const;
};

// `count` pinhole views on a circle (or arc) around the box centre, looking
// at it, named "orbit_000", ...; each camera's image y points along -up, so
// `up` is at the top of every image.
std::vector<NamedView> OrbitViews(const MapSet& maps, const OrbitOptions& options);

// The same turntable around any box: [0,1]^3 -> world (affine).
std::vector<NamedView> OrbitViews(const glm::dmat4& world_from_box, const OrbitOptions& options);

// An up direction as a user types it: "x", "y", "z", "-x", "-y", "-z", or
// three numbers ("0,-1,0" or "0 -1 0"); normalised. InputError naming
// `where` otherwise (zero, not finite, not three numbers).
glm::dvec3 ParseUp(const std::string& text, const std::string& where);

// The one orbit camera: every orbit of the product (the single image of
// `ibr displace`, `ibr volume` and `ibr deform`, the turntables of `ibr
// render` and scene files, the interactive viewer's) is this eye. It looks
// at `centre` from `distance` (0 = framed: a sphere of `radius` just fills
// the vertical field of view), `elevation_deg` above the plane
// perpendicular to `up`, `azimuth_deg` around `up` counted from h1 towards
// up x h1, where h1 is the axis after up's largest component (x -> y -> z
// -> x) made perpendicular to up: x for up z, z for up y, y for up x. `up`
// is at the top of the image (any non-zero direction; normalised).
struct OrbitCamera {
  double elevation_deg = 35;
  double azimuth_deg = -60;
  double distance = 0;  // world units from the centre; 0 = framed
  double fov_deg = 40;  // full vertical field of view
  glm::dvec3 up{0, 0, 1};
  void Check() const;
};
// A width x height pinhole (square pixels, principal point at the centre).
ViewCamera OrbitCameraView(const glm::dvec3& centre, double radius, const OrbitCamera& orbit,
                           int width, int height);
inline ViewCamera OrbitCameraView(const glm::dvec3& centre, double radius, const OrbitCamera& orbit,
                                  int size_px) {
  return OrbitCameraView(centre, radius, orbit, size_px, size_px);
}
// The orbit's pass inputs around the sphere: clip range from 1.5 radii in
// front of the centre (never at or behind the eye) to 1.5 radii behind it.
render::ViewSetup OrbitViewSetup(const glm::dvec3& centre, double radius, const OrbitCamera& orbit,
                                 int size_px);
// An axis-aligned up as `--up` of `ibr displace` and `ibr volume` takes it:
// "x", "y", "z", "-x", "-y", "-z" (InputError naming `where` otherwise).
glm::vec3 UpAxisFromName(const std::string& name, std::string_view where);

// The views a scene file's "cameras" names (scene/scene.h): an orbit around
// `world_from_box`, a dataset's cameras (capture::ReadCameras: images not
// needed) resized to its width, or the explicit list.
std::vector<NamedView> SceneCameraViews(const scene::Cameras& cameras,
                                        const glm::dmat4& world_from_box);

// The mean viewing direction of `views` (unit, world; the cameras' z axes),
// for an arc around the input views; zero when they cancel out.
glm::dvec3 MeanViewDirection(const std::vector<ViewCamera>& views);

// Conversions between camera types (the one place they happen).
capture::Camera CaptureCamera(const MapCamera& camera);
capture::Rigid3 RigidFromMat4(const glm::dmat4& cam_from_world);  // inverse of ibr::Mat4From
ViewCamera ViewCameraFrom(const capture::RigView& view);
// A rig view with a clip range that holds `bounds` (for capture::RenderView).
capture::RigView RigViewFor(const ViewCamera& view, const capture::Bounds& bounds,
                            const std::string& name);
// Pass inputs for a view: clip range = camera z range of the bounds' corners,
// widened by 5 %, near kept in front of the camera.
render::ViewSetup ViewSetupFor(const ViewCamera& view, const capture::Bounds& bounds);
// The world bounds of the unit box carried by `world_from_box` (its 8 corners).
capture::Bounds BoxBounds(const glm::dmat4& world_from_box);

// A rendered camera-z image (0 = empty) as a dataset's depth: an
// orthographic view also shows what lies behind its image plane (camera
// z < 0, inside its clip range; e.g. a cube rig's camera placed inside
// another dataset's box), which a dataset cannot hold (depth is 0 = invalid,
// or positive). Those pixels get invalid depth (0), keeping their colour and
// mask; every other value is copied. The one place rendered frames become
// dataset depth (ibr render, scene files, ibr deform).
core::ImageF DatasetDepth(const core::ImageF& camera_z);

// A camera scaled to `width` pixels wide (height keeps the aspect ratio).
MapCamera ResizeCamera(const MapCamera& camera, int width);

}  // namespace ibr
