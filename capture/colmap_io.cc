#include "capture/colmap_io.h"

#include <fmt/format.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace capture::colmap {
namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little,
              "COLMAP binary files are little-endian; this reader assumes a little-endian host");

namespace {

// ---------------------------------------------------------------- text ----

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() &&
         (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string_view> Split(std::string_view s) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    if (j > i) tokens.push_back(s.substr(i, j - i));
    i = j;
  }
  return tokens;
}

// Line-oriented reader that knows where it is, for messages.
class LineReader {
 public:
  LineReader(std::istream& in, std::string where) : in_(in), where_(std::move(where)) {}

  // Next line that is neither empty nor a comment; false at the end.
  bool NextContentLine(std::string& line) {
    while (NextLine(line)) {
      const std::string_view t = Trim(line);
      if (!t.empty() && t.front() != '#') return true;
    }
    return false;
  }
  // The very next line (may be empty); false at the end of the stream.
  bool NextLine(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_number_;
    return true;
  }

  template <typename... Args>
  [[noreturn]] void Fail(fmt::format_string<Args...> format, Args&&... args) const {
    core::ThrowInputError(where_, "line {}: {}", line_number_,
                          fmt::format(format, std::forward<Args>(args)...));
  }

  template <typename T>
  T Parse(std::string_view token, const char* what) const {
    T value{};
    const char* begin = token.data();
    const char* end = token.data() + token.size();
    if constexpr (std::is_floating_point_v<T>) {
      const auto [ptr, ec] = std::from_chars(begin, end, value);
      if (ec != std::errc() || ptr != end) Fail("{} '{}' is not a number", what, token);
      if (!std::isfinite(value)) Fail("{} '{}' is not finite", what, token);
    } else {
      const auto [ptr, ec] = std::from_chars(begin, end, value);
      if (ec != std::errc() || ptr != end) Fail("{} '{}' is not a valid integer", what, token);
    }
    return value;
  }

 private:
  std::istream& in_;
  std::string where_;
  int line_number_ = 0;
};

std::string Where(const char* function, const std::string& name) {
  return fmt::format("{}: '{}'", function, name);
}

Camera CameraFromModel(int model_id_or_minus1, std::string_view model_name, int64_t width,
                       int64_t height, std::vector<double> params, const std::string& where) {
  std::optional<CameraModel> model;
  if (model_id_or_minus1 >= 0) {
    model = CameraModelFromColmapId(model_id_or_minus1);
    if (!model) core::ThrowInputError(where, "unknown camera model id {}", model_id_or_minus1);
  } else {
    model = CameraModelFromName(model_name);
    if (!model || *model == CameraModel::kOrthographic) {
      core::ThrowInputError(where, "unknown camera model '{}'", model_name);
    }
  }
  if (width <= 0 || height <= 0 || width > 65536 || height > 65536) {
    core::ThrowInputError(where, "camera size {}x{} is not in 1..65536", width, height);
  }
  Camera camera{*model, static_cast<int>(width), static_cast<int>(height), std::move(params)};
  camera.Check(where);
  return camera;
}

void CheckPose(const std::array<double, 4>& q, const std::array<double, 3>& t,
               const std::string& where) {
  for (double v : q)
    if (!std::isfinite(v)) core::ThrowInputError(where, "quaternion is not finite");
  for (double v : t)
    if (!std::isfinite(v)) core::ThrowInputError(where, "translation is not finite");
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (norm < 1e-12) core::ThrowInputError(where, "quaternion has zero length");
}

std::string FormatDouble(double v) { return fmt::format("{}", v); }

// -------------------------------------------------------------- binary ----

class BinaryReader {
 public:
  BinaryReader(std::istream& in, std::string where) : in_(in), where_(std::move(where)) {}
  template <typename T>
  T Read(const char* what) {
    T value;
    in_.read(reinterpret_cast<char*>(&value), sizeof(T));
    if (in_.gcount() != static_cast<std::streamsize>(sizeof(T))) {
      core::ThrowInputError(where_, "truncated: file ends inside {} (byte {})", what, offset_);
    }
    offset_ += sizeof(T);
    return value;
  }
  double ReadFinite(const char* what) {
    const double v = Read<double>(what);
    if (!std::isfinite(v))
      core::ThrowInputError(where_, "{} at byte {} is not finite", what, offset_ - 8);
    return v;
  }
  std::string ReadString(const char* what) {
    std::string s;
    char c;
    while (true) {
      in_.read(&c, 1);
      if (in_.gcount() != 1)
        core::ThrowInputError(where_, "truncated: file ends inside {} (byte {})", what, offset_);
      ++offset_;
      if (c == '\0') break;
      s.push_back(c);
    }
    return s;
  }
  void ExpectEnd() {
    if (in_.peek() != std::char_traits<char>::eof()) {
      core::ThrowInputError(where_, "unexpected trailing bytes after byte {}", offset_);
    }
  }
  const std::string& where() const { return where_; }

 private:
  std::istream& in_;
  std::string where_;
  uint64_t offset_ = 0;
};

template <typename T>
void Put(std::ostream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

}  // namespace

// ------------------------------------------------------------ model check ----

void SparseModel::Check(const std::string& where) const {
  for (const auto& [id, image] : images) {
    if (!cameras.contains(image.camera_id)) {
      core::ThrowInputError(where, "image {} ('{}') names unknown camera {}", id, image.name,
                            image.camera_id);
    }
  }
  for (const auto& [id, point] : points3D) {
    for (const auto& el : point.track) {
      const auto it = images.find(el.image_id);
      if (it == images.end())
        core::ThrowInputError(where, "point {} track names unknown image {}", id, el.image_id);
      if (el.point2D_idx >= it->second.points2D.size()) {
        core::ThrowInputError(where,
                              "point {} track index {} out of range for image {} ({} points)", id,
                              el.point2D_idx, el.image_id, it->second.points2D.size());
      }
    }
  }
}

// ------------------------------------------------------------------ text ----

std::map<uint32_t, Camera> ReadCamerasText(std::istream& in, const std::string& name) {
  const std::string where = Where("ReadCamerasText", name);
  LineReader reader(in, where);
  std::map<uint32_t, Camera> cameras;
  std::string line;
  while (reader.NextContentLine(line)) {
    const auto tokens = Split(line);
    if (tokens.size() < 4)
      reader.Fail("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS..., got {} fields", tokens.size());
    const auto id = reader.Parse<uint32_t>(tokens[0], "CAMERA_ID");
    const auto width = reader.Parse<int64_t>(tokens[2], "WIDTH");
    const auto height = reader.Parse<int64_t>(tokens[3], "HEIGHT");
    std::vector<double> params;
    for (size_t i = 4; i < tokens.size(); ++i)
      params.push_back(reader.Parse<double>(tokens[i], "parameter"));
    Camera camera;
    try {
      camera = CameraFromModel(-1, tokens[1], width, height, std::move(params), "camera");
    } catch (const core::InputError& e) {
      reader.Fail("{}", e.what());
    }
    if (!cameras.emplace(id, std::move(camera)).second) reader.Fail("duplicate CAMERA_ID {}", id);
  }
  return cameras;
}

std::map<uint32_t, Image> ReadImagesText(std::istream& in, const std::string& name) {
  const std::string where = Where("ReadImagesText", name);
  LineReader reader(in, where);
  std::map<uint32_t, Image> images;
  std::string line;
  while (reader.NextContentLine(line)) {
    const auto tokens = Split(line);
    if (tokens.size() < 10)
      reader.Fail("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, got {} fields",
                  tokens.size());
    Image image;
    image.image_id = reader.Parse<uint32_t>(tokens[0], "IMAGE_ID");
    for (int k = 0; k < 4; ++k) image.qvec[k] = reader.Parse<double>(tokens[1 + k], "quaternion");
    for (int k = 0; k < 3; ++k) image.tvec[k] = reader.Parse<double>(tokens[5 + k], "translation");
    image.camera_id = reader.Parse<uint32_t>(tokens[8], "CAMERA_ID");
    // The name is the rest of the line (COLMAP allows no spaces, but keep them).
    const size_t name_pos = static_cast<size_t>(tokens[9].data() - line.data());
    image.name = std::string(Trim(std::string_view(line).substr(name_pos)));
    try {
      CheckPose(image.qvec, image.tvec, "pose");
    } catch (const core::InputError& e) {
      reader.Fail("{}", e.what());
    }
    if (!reader.NextLine(line)) reader.Fail("missing POINTS2D line for image {}", image.image_id);
    const auto pts = Split(line);
    if (pts.size() % 3 != 0)
      reader.Fail("POINTS2D line has {} fields, not a multiple of 3", pts.size());
    for (size_t i = 0; i < pts.size(); i += 3) {
      Point2D p;
      p.x = reader.Parse<double>(pts[i], "X");
      p.y = reader.Parse<double>(pts[i + 1], "Y");
      const auto id = reader.Parse<int64_t>(pts[i + 2], "POINT3D_ID");
      if (id < -1) reader.Fail("POINT3D_ID {} is negative", id);
      p.point3D_id = id == -1 ? kInvalidPoint3DId : static_cast<uint64_t>(id);
      image.points2D.push_back(p);
    }
    const uint32_t id = image.image_id;
    if (!images.emplace(id, std::move(image)).second) reader.Fail("duplicate IMAGE_ID {}", id);
  }
  return images;
}

std::map<uint64_t, Point3D> ReadPoints3DText(std::istream& in, const std::string& name) {
  const std::string where = Where("ReadPoints3DText", name);
  LineReader reader(in, where);
  std::map<uint64_t, Point3D> points;
  std::string line;
  while (reader.NextContentLine(line)) {
    const auto tokens = Split(line);
    if (tokens.size() < 8 || (tokens.size() - 8) % 2 != 0) {
      reader.Fail("expected POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)*, got {} fields",
                  tokens.size());
    }
    Point3D p;
    p.point3D_id = reader.Parse<uint64_t>(tokens[0], "POINT3D_ID");
    for (int k = 0; k < 3; ++k) p.xyz[k] = reader.Parse<double>(tokens[1 + k], "coordinate");
    for (int k = 0; k < 3; ++k) {
      const auto c = reader.Parse<int>(tokens[4 + k], "colour");
      if (c < 0 || c > 255) reader.Fail("colour {} outside 0..255", c);
      p.rgb[k] = static_cast<uint8_t>(c);
    }
    p.error = reader.Parse<double>(tokens[7], "ERROR");
    for (size_t i = 8; i < tokens.size(); i += 2) {
      p.track.push_back({reader.Parse<uint32_t>(tokens[i], "IMAGE_ID"),
                         reader.Parse<uint32_t>(tokens[i + 1], "POINT2D_IDX")});
    }
    const uint64_t id = p.point3D_id;
    if (!points.emplace(id, std::move(p)).second) reader.Fail("duplicate POINT3D_ID {}", id);
  }
  return points;
}

void WriteCamerasText(std::ostream& out, const std::map<uint32_t, Camera>& cameras) {
  out << "# Camera list with one line of data per camera:\n"
         "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      << "# Number of cameras: " << cameras.size() << "\n";
  for (const auto& [id, c] : cameras) {
    IBR_CHECK(!c.orthographic());
    out << id << ' ' << CameraModelName(c.model) << ' ' << c.width << ' ' << c.height;
    for (double p : c.params) out << ' ' << FormatDouble(p);
    out << '\n';
  }
}

void WriteImagesText(std::ostream& out, const std::map<uint32_t, Image>& images) {
  out << "# Image list with two lines of data per image:\n"
         "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
         "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      << "# Number of images: " << images.size() << "\n";
  for (const auto& [id, im] : images) {
    out << id;
    for (double q : im.qvec) out << ' ' << FormatDouble(q);
    for (double t : im.tvec) out << ' ' << FormatDouble(t);
    out << ' ' << im.camera_id << ' ' << im.name << '\n';
    bool first = true;
    for (const auto& p : im.points2D) {
      if (!first) out << ' ';
      first = false;
      out << FormatDouble(p.x) << ' ' << FormatDouble(p.y) << ' ';
      if (p.point3D_id == kInvalidPoint3DId)
        out << -1;
      else
        out << p.point3D_id;
    }
    out << '\n';
  }
}

void WritePoints3DText(std::ostream& out, const std::map<uint64_t, Point3D>& points) {
  out << "# 3D point list with one line of data per point:\n"
         "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      << "# Number of points: " << points.size() << "\n";
  for (const auto& [id, p] : points) {
    out << id;
    for (double x : p.xyz) out << ' ' << FormatDouble(x);
    for (uint8_t c : p.rgb) out << ' ' << static_cast<int>(c);
    out << ' ' << FormatDouble(p.error);
    for (const auto& el : p.track) out << ' ' << el.image_id << ' ' << el.point2D_idx;
    out << '\n';
  }
}

// ---------------------------------------------------------------- binary ----

std::map<uint32_t, Camera> ReadCamerasBinary(std::istream& in, const std::string& name) {
  BinaryReader reader(in, Where("ReadCamerasBinary", name));
  std::map<uint32_t, Camera> cameras;
  const uint64_t count = reader.Read<uint64_t>("num_cameras");
  for (uint64_t i = 0; i < count; ++i) {
    const auto id = reader.Read<uint32_t>("camera_id");
    const auto model_id = reader.Read<int32_t>("model_id");
    const auto width = reader.Read<uint64_t>("width");
    const auto height = reader.Read<uint64_t>("height");
    const auto model = CameraModelFromColmapId(model_id);
    if (!model)
      core::ThrowInputError(reader.where(), "camera {}: unknown model id {}", id, model_id);
    std::vector<double> params(CameraModelParamCount(*model));
    for (double& p : params) p = reader.Read<double>("camera params");
    const std::string ctx = fmt::format("{}: camera {}", reader.where(), id);
    const int64_t w = width > 65536 ? -1 : static_cast<int64_t>(width);
    const int64_t h = height > 65536 ? -1 : static_cast<int64_t>(height);
    Camera camera = CameraFromModel(model_id, "", w, h, std::move(params), ctx);
    if (!cameras.emplace(id, std::move(camera)).second)
      core::ThrowInputError(reader.where(), "duplicate camera id {}", id);
  }
  reader.ExpectEnd();
  return cameras;
}

std::map<uint32_t, Image> ReadImagesBinary(std::istream& in, const std::string& name) {
  BinaryReader reader(in, Where("ReadImagesBinary", name));
  std::map<uint32_t, Image> images;
  const uint64_t count = reader.Read<uint64_t>("num_reg_images");
  for (uint64_t i = 0; i < count; ++i) {
    Image image;
    image.image_id = reader.Read<uint32_t>("image_id");
    for (double& q : image.qvec) q = reader.Read<double>("qvec");
    for (double& t : image.tvec) t = reader.Read<double>("tvec");
    CheckPose(image.qvec, image.tvec, fmt::format("{}: image {}", reader.where(), image.image_id));
    image.camera_id = reader.Read<uint32_t>("camera_id");
    image.name = reader.ReadString("image name");
    const uint64_t n = reader.Read<uint64_t>("num_points2D");
    for (uint64_t k = 0; k < n; ++k) {
      Point2D p;
      p.x = reader.ReadFinite("point2D x");
      p.y = reader.ReadFinite("point2D y");
      p.point3D_id = reader.Read<uint64_t>("point3D_id");
      image.points2D.push_back(p);
    }
    const uint32_t id = image.image_id;
    if (!images.emplace(id, std::move(image)).second)
      core::ThrowInputError(reader.where(), "duplicate image id {}", id);
  }
  reader.ExpectEnd();
  return images;
}

std::map<uint64_t, Point3D> ReadPoints3DBinary(std::istream& in, const std::string& name) {
  BinaryReader reader(in, Where("ReadPoints3DBinary", name));
  std::map<uint64_t, Point3D> points;
  const uint64_t count = reader.Read<uint64_t>("num_points");
  for (uint64_t i = 0; i < count; ++i) {
    Point3D p;
    p.point3D_id = reader.Read<uint64_t>("point3D_id");
    for (double& x : p.xyz) x = reader.ReadFinite("xyz");
    for (uint8_t& c : p.rgb) c = reader.Read<uint8_t>("rgb");
    p.error = reader.Read<double>("error");
    const uint64_t n = reader.Read<uint64_t>("track_length");
    for (uint64_t k = 0; k < n; ++k) {
      TrackElement el;
      el.image_id = reader.Read<uint32_t>("track image_id");
      el.point2D_idx = reader.Read<uint32_t>("track point2D_idx");
      p.track.push_back(el);
    }
    const uint64_t id = p.point3D_id;
    if (!points.emplace(id, std::move(p)).second)
      core::ThrowInputError(reader.where(), "duplicate point id {}", id);
  }
  reader.ExpectEnd();
  return points;
}

void WriteCamerasBinary(std::ostream& out, const std::map<uint32_t, Camera>& cameras) {
  Put<uint64_t>(out, cameras.size());
  for (const auto& [id, c] : cameras) {
    IBR_CHECK(!c.orthographic());
    Put<uint32_t>(out, id);
    Put<int32_t>(out, static_cast<int32_t>(c.model));
    Put<uint64_t>(out, static_cast<uint64_t>(c.width));
    Put<uint64_t>(out, static_cast<uint64_t>(c.height));
    for (double p : c.params) Put<double>(out, p);
  }
}

void WriteImagesBinary(std::ostream& out, const std::map<uint32_t, Image>& images) {
  Put<uint64_t>(out, images.size());
  for (const auto& [id, im] : images) {
    Put<uint32_t>(out, id);
    for (double q : im.qvec) Put<double>(out, q);
    for (double t : im.tvec) Put<double>(out, t);
    Put<uint32_t>(out, im.camera_id);
    out.write(im.name.c_str(), static_cast<std::streamsize>(im.name.size() + 1));
    Put<uint64_t>(out, im.points2D.size());
    for (const auto& p : im.points2D) {
      Put<double>(out, p.x);
      Put<double>(out, p.y);
      Put<uint64_t>(out, p.point3D_id);
    }
  }
}

void WritePoints3DBinary(std::ostream& out, const std::map<uint64_t, Point3D>& points) {
  Put<uint64_t>(out, points.size());
  for (const auto& [id, p] : points) {
    Put<uint64_t>(out, id);
    for (double x : p.xyz) Put<double>(out, x);
    for (uint8_t c : p.rgb) Put<uint8_t>(out, c);
    Put<double>(out, p.error);
    Put<uint64_t>(out, p.track.size());
    for (const auto& el : p.track) {
      Put<uint32_t>(out, el.image_id);
      Put<uint32_t>(out, el.point2D_idx);
    }
  }
}

// ----------------------------------------------------------------- model ----

bool IsSparseModelDir(const fs::path& dir) {
  return fs::is_regular_file(dir / "cameras.bin") || fs::is_regular_file(dir / "cameras.txt");
}

SparseModel ReadSparseModel(const fs::path& dir) {
  SparseModel model;
  if (fs::is_regular_file(dir / "cameras.bin")) {
    model.cameras = ReadFile(dir / "cameras.bin", ReadCamerasBinary);
    model.images = ReadFile(dir / "images.bin", ReadImagesBinary);
    model.points3D = ReadFile(dir / "points3D.bin", ReadPoints3DBinary);
  } else if (fs::is_regular_file(dir / "cameras.txt")) {
    model.cameras = ReadFile(dir / "cameras.txt", ReadCamerasText);
    model.images = ReadFile(dir / "images.txt", ReadImagesText);
    model.points3D = ReadFile(dir / "points3D.txt", ReadPoints3DText);
  } else {
    core::ThrowFileError("ReadSparseModel", dir,
                         "no cameras.bin or cameras.txt (not a COLMAP model)");
  }
  model.Check(fmt::format("ReadSparseModel: '{}'", dir.string()));
  return model;
}

void WriteSparseModel(const fs::path& dir, const SparseModel& model, ModelFormat format) {
  if (format == ModelFormat::kText) {
    core::AtomicWriteStream(dir / "cameras.txt",
                            [&](std::ostream& o) { WriteCamerasText(o, model.cameras); });
    core::AtomicWriteStream(dir / "images.txt",
                            [&](std::ostream& o) { WriteImagesText(o, model.images); });
    core::AtomicWriteStream(dir / "points3D.txt",
                            [&](std::ostream& o) { WritePoints3DText(o, model.points3D); });
  } else {
    core::AtomicWriteStream(dir / "cameras.bin",
                            [&](std::ostream& o) { WriteCamerasBinary(o, model.cameras); });
    core::AtomicWriteStream(dir / "images.bin",
                            [&](std::ostream& o) { WriteImagesBinary(o, model.images); });
    core::AtomicWriteStream(dir / "points3D.bin",
                            [&](std::ostream& o) { WritePoints3DBinary(o, model.points3D); });
  }
}

// ------------------------------------------------------------ dense maps ----

core::ImageF ReadDenseMap(std::istream& in, const std::string& name) {
  const std::string where = Where("ReadDenseMap", name);
  int64_t dims[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    std::string digits;
    char c;
    while (true) {
      in.read(&c, 1);
      if (in.gcount() != 1) core::ThrowInputError(where, "truncated header (expected \"W&H&C&\")");
      if (c == '&') break;
      if (c < '0' || c > '9' || digits.size() >= 9) {
        core::ThrowInputError(where, "bad header: expected \"W&H&C&\" with decimal sizes");
      }
      digits.push_back(c);
    }
    if (digits.empty()) core::ThrowInputError(where, "bad header: empty size field");
    dims[k] = std::stoll(digits);
  }
  const int64_t w = dims[0], h = dims[1], channels = dims[2];
  if (w <= 0 || h <= 0 || w > 65536 || h > 65536)
    core::ThrowInputError(where, "map size {}x{} not in 1..65536", w, h);
  if (channels != 1 && channels != 3)
    core::ThrowInputError(where, "{} channels (expected 1 for depth, 3 for normals)", channels);
  const size_t count = static_cast<size_t>(w * h * channels);
  // Know how many bytes there are before allocating.
  const auto start = in.tellg();
  if (start >= 0) {
    in.seekg(0, std::ios::end);
    const auto end = in.tellg();
    in.seekg(start);
    const auto available = static_cast<uint64_t>(end - start);
    if (available < count * sizeof(float)) {
      core::ThrowInputError(where, "truncated: {}x{}x{} map needs {} bytes of data, file has {}", w,
                            h, channels, count * sizeof(float), available);
    }
    if (available > count * sizeof(float)) {
      core::ThrowInputError(where, "{} unexpected trailing bytes after the {}x{}x{} map",
                            available - count * sizeof(float), w, h, channels);
    }
  }
  std::vector<float> planar(count);
  in.read(reinterpret_cast<char*>(planar.data()),
          static_cast<std::streamsize>(count * sizeof(float)));
  if (static_cast<size_t>(in.gcount()) != count * sizeof(float)) {
    core::ThrowInputError(where, "truncated: {}x{}x{} map needs {} bytes of data", w, h, channels,
                          count * sizeof(float));
  }
  core::ImageF map(static_cast<int>(w), static_cast<int>(h), static_cast<int>(channels));
  const size_t plane = static_cast<size_t>(w * h);
  for (size_t c = 0; c < static_cast<size_t>(channels); ++c) {
    for (size_t i = 0; i < plane; ++i) map.data()[i * channels + c] = planar[c * plane + i];
  }
  return map;
}

core::ImageF ReadDenseMap(const fs::path& path) {
  return ReadFile(path, [](std::istream& in, const std::string& n) { return ReadDenseMap(in, n); });
}

void WriteDenseMap(std::ostream& out, const core::ImageF& map) {
  IBR_CHECK(!map.empty());
  out << map.width() << '&' << map.height() << '&' << map.channels() << '&';
  const size_t plane = map.pixel_count();
  const size_t channels = static_cast<size_t>(map.channels());
  std::vector<float> planar(plane * channels);
  for (size_t c = 0; c < channels; ++c) {
    for (size_t i = 0; i < plane; ++i) planar[c * plane + i] = map.data()[i * channels + c];
  }
  out.write(reinterpret_cast<const char*>(planar.data()),
            static_cast<std::streamsize>(planar.size() * sizeof(float)));
}

void WriteDenseMap(const fs::path& path, const core::ImageF& map) {
  core::AtomicWriteStream(path, [&](std::ostream& out) { WriteDenseMap(out, map); });
}

// ---------------------------------------------------------------- configs ----

std::vector<std::string> ReadFusionConfig(std::istream& in, const std::string& name) {
  const std::string where = Where("ReadFusionConfig", name);
  std::vector<std::string> names;
  std::set<std::string> seen;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view t = Trim(line);
    if (t.empty()) continue;
    if (t.find('\0') != std::string_view::npos)
      core::ThrowInputError(where, "line {}: NUL byte in image name", line_number);
    if (!seen.insert(std::string(t)).second)
      core::ThrowInputError(where, "line {}: duplicate image '{}'", line_number, t);
    names.emplace_back(t);
  }
  if (names.empty()) core::ThrowInputError(where, "no image names");
  return names;
}

void WriteFusionConfig(std::ostream& out, const std::vector<std::string>& image_names) {
  for (const auto& n : image_names) out << n << '\n';
}

std::vector<PatchMatchEntry> ReadPatchMatchConfig(std::istream& in, const std::string& name) {
  const std::string where = Where("ReadPatchMatchConfig", name);
  std::vector<PatchMatchEntry> entries;
  std::string line;
  int line_number = 0;
  std::optional<PatchMatchEntry> pending;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view t = Trim(line);
    if (t.empty()) continue;
    if (t.find('\0') != std::string_view::npos)
      core::ThrowInputError(where, "line {}: NUL byte", line_number);
    if (!pending) {
      pending = PatchMatchEntry{std::string(t), {}};
    } else {
      pending->sources = std::string(t);
      entries.push_back(std::move(*pending));
      pending.reset();
    }
  }
  if (pending)
    core::ThrowInputError(where, "line {}: image '{}' has no source line", line_number,
                          pending->image_name);
  if (entries.empty()) core::ThrowInputError(where, "no entries");
  return entries;
}

void WritePatchMatchConfig(std::ostream& out, const std::vector<PatchMatchEntry>& entries) {
  for (const auto& e : entries) out << e.image_name << '\n' << e.sources << '\n';
}

}  // namespace capture::colmap
