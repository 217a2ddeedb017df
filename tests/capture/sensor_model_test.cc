// The depth sensor model (capture/sensor_model.h) against what each of its
// effects must do to a depth map whose truth is known: a plane facing the
// camera, a step, a tilted plane, a square object on an empty background.
// Statistics are checked against their analytic values with bounds of
// several standard errors; every spec error names the key.
#include "capture/sensor_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "capture/dataset.h"
#include "core/error.h"

namespace capture {
namespace {

constexpr int kSize = 128;

Camera Pinhole() { return Camera::Pinhole(kSize, kSize, 100, 100, kSize / 2.0, kSize / 2.0); }

// Camera looking along +z from the origin (cam = world).
const Rigid3 kIdentity;

struct Maps {
  core::ImageF depth{kSize, kSize, 1, 0.0f};
  core::Image8 mask{kSize, kSize, 1, 0};
  core::ImageF normal{kSize, kSize, 3, 0.0f};
};

// A square of side `side` px at depth z in the middle, facing the camera
// (normal -z towards it), on an empty background.
Maps Square(float z, int side) {
  Maps m;
  const int lo = (kSize - side) / 2;
  for (int y = lo; y < lo + side; ++y) {
    for (int x = lo; x < lo + side; ++x) {
      m.depth.at(x, y) = z;
      m.mask.at(x, y) = 255;
      m.normal.at(x, y, 2) = -1;
    }
  }
  return m;
}

SensorModel Parse(const std::string& spec) { return ParseSensorModel(spec, 2.0, 1.0); }

void Apply(const SensorModel& model, Maps& m, size_t view = 0) {
  ApplySensorModel(model, Pinhole(), kIdentity, 0.5, 10, view, m.depth, m.mask, m.normal);
}

TEST(SensorModel, SpecParsesLengthsInSceneUnitsOrPercentOfTheDiagonal) {
  const SensorModel m = Parse(
      "sigma=0.5%,model=quadratic,quantize=0.001,edge=2,grazing=75,holes=0.02,hole-radius=3,"
      "flying=0.5,outliers=0.001,mask=depth,seed=7");
  EXPECT_DOUBLE_EQ(m.sigma, 0.01);  // 0.5 % of 2
  EXPECT_EQ(m.noise, SensorModel::Noise::kQuadratic);
  EXPECT_DOUBLE_EQ(m.quantize, 0.001);
  EXPECT_EQ(m.edge, 2);
  EXPECT_DOUBLE_EQ(m.grazing_deg, 75);
  EXPECT_DOUBLE_EQ(m.holes, 0.02);
  EXPECT_EQ(m.hole_radius, 3);
  EXPECT_DOUBLE_EQ(m.flying, 0.5);
  EXPECT_DOUBLE_EQ(m.outliers, 0.001);
  EXPECT_TRUE(m.mask_from_depth);
  EXPECT_EQ(m.seed, 7u);
  EXPECT_TRUE(Parse("").empty());
  EXPECT_NE(m.Describe().find("quadratic"), std::string::npos) << m.Describe();
  // Recorded in dataset.json and read back exactly.
  EXPECT_EQ(SensorModel::FromJson(m.ToJson(), "test"), m);
}

TEST(SensorModel, BadSpecsNameTheKey) {
  for (const auto& [spec, says] : std::vector<std::pair<std::string, std::string>>{
           {"sigma=abc", "sigma=abc: not a number"},
           {"sigm=0.1", "unknown key 'sigm'"},
           {"holes", "not key=value"},
           {"holes=0.9", "holes=0.9 outside [0, 0.5]"},
           {"sigma=-1", "sigma=-1"},
           {"grazing=95", "grazing=95"},
           {"edge=1.5", "edge=1.5: not a whole number"},
           {"model=cubic", "model=cubic"},
           {"mask=maybe", "mask=maybe"}}) {
    try {
      Parse(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--noise '" + spec + "'"), std::string::npos)
          << e.what();
    }
  }
}

TEST(SensorModel, NoiseHasItsStandardDeviationConstantOrQuadraticInDepth) {
  for (const auto& [spec, z, expected] : std::vector<std::tuple<std::string, float, double>>{
           {"sigma=0.01", 2.0f, 0.01},
           {"sigma=0.01,model=quadratic", 2.0f, 0.04},  // (2 / z_ref 1)^2
           {"sigma=0.01,model=quadratic", 0.5f, 0.0025}}) {
    Maps m = Square(z, 100);
    Apply(Parse(spec), m);
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int y = 20; y < 108; ++y) {
      for (int x = 20; x < 108; ++x) {
        const double d = m.depth.at(x, y) - z;
        sum += d;
        sum2 += d * d;
        ++n;
      }
    }
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    std::printf("%s at z %.2f: sd %.5f (expected %.5f), mean %+.6f over %d samples\n", spec.c_str(),
                z, sd, expected, mean, n);
    // 7744 samples: the standard error of the sd is 0.8 %, of the mean 1.1 % of sd.
    EXPECT_NEAR(sd, expected, 0.05 * expected) << spec << " at " << z;
    EXPECT_NEAR(mean, 0, 0.06 * expected) << spec << " at " << z;
    EXPECT_EQ(m.mask, Square(z, 100).mask) << "the mask is exact unless asked";
  }
}

TEST(SensorModel, QuantisationRoundsToTheStep) {
  Maps m = Square(1.23456f, 40);
  Apply(Parse("quantize=0.01"), m);
  EXPECT_NEAR(m.depth.at(64, 64), 1.23f, 1e-6f);
  EXPECT_EQ(m.depth.at(0, 0), 0.0f);
}

TEST(SensorModel, EdgesLoseTheirDepthTheInsideKeepsIt) {
  const Maps clean = Square(2.0f, 40);  // pixels 44..83
  for (int edge : {1, 3}) {
    Maps m = clean;
    Apply(Parse("edge=" + std::to_string(edge)), m);
    for (int x = 44; x < 84; ++x) {
      const int from_rim = std::min(x - 44, 83 - x);
      EXPECT_EQ(m.depth.at(x, 64) == 0, from_rim < edge) << "edge " << edge << " x " << x;
    }
    EXPECT_EQ(m.mask, clean.mask);
  }
  // A step inside the object is an edge too, on its near side only.
  Maps step = Square(2.0f, 40);
  for (int y = 44; y < 84; ++y)
    for (int x = 64; x < 84; ++x) step.depth.at(x, y) = 3.0f;
  Apply(Parse("edge=1"), step);
  EXPECT_EQ(step.depth.at(63, 64), 0.0f);  // near side of the step
  EXPECT_EQ(step.depth.at(64, 64), 3.0f);  // far side keeps its depth
  EXPECT_EQ(step.depth.at(60, 64), 2.0f);
}

TEST(SensorModel, FlyingPixelsLieBetweenTheSides) {
  Maps m = Square(2.0f, 40);
  for (int y = 44; y < 84; ++y)
    for (int x = 64; x < 84; ++x) m.depth.at(x, y) = 3.0f;
  Apply(Parse("flying=1"), m);
  int between = 0, behind = 0;
  for (int y = 45; y < 83; ++y) {
    const float z = m.depth.at(63, y);
    EXPECT_TRUE(z >= 2.0f && z <= 3.0f) << z;
    between += z > 2.0f && z < 3.0f;
  }
  // At the silhouette the empty neighbour takes a depth behind the edge.
  for (int y = 45; y < 83; ++y) {
    const float z = m.depth.at(43, y);
    EXPECT_TRUE(z == 0 || (z >= 2.0f && z <= 2.5f)) << z;
    behind += z > 0;
  }
  std::printf(
      "flying=1: %d of 38 step pixels between the sides, %d of 38 empty pixels behind "
      "the silhouette\n",
      between, behind);
  EXPECT_GT(between, 30);
  EXPECT_GT(behind, 30);
  EXPECT_EQ(m.mask.at(43, 60), 0) << "the mask stays exact";
}

TEST(SensorModel, GrazingSurfacesLoseTheirDepth) {
  // The whole square's normal tilted from the view axis by `angle`.
  for (const auto& [angle, dropped] : {std::pair{60.0, false}, std::pair{80.0, true}}) {
    Maps m = Square(2.0f, 20);
    const double a = angle * M_PI / 180;
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        if (m.mask.at(x, y) == 0) continue;
        m.normal.at(x, y, 0) = static_cast<float>(std::sin(a));
        m.normal.at(x, y, 2) = static_cast<float>(-std::cos(a));
      }
    }
    Apply(Parse("grazing=75"), m);
    // The centre pixel's ray is the view axis: the angle is the tilt.
    EXPECT_EQ(m.depth.at(64, 64) == 0, dropped) << angle;
  }
}

TEST(SensorModel, HolesAndOutliersTakeTheirFractionAndMaskDepthFollows) {
  const Maps clean = Square(2.0f, 100);
  Maps m = clean;
  Apply(Parse("holes=0.05,hole-radius=2"), m);
  int missing = 0;
  for (size_t p = 0; p < m.depth.pixel_count(); ++p)
    missing += clean.depth.data()[p] > 0 && m.depth.data()[p] == 0;
  EXPECT_NEAR(missing, 500, 1);  // 5 % of 10000
  // Holes are blobs: most missing pixels have a missing neighbour.
  int clustered = 0;
  for (int y = 1; y + 1 < kSize; ++y) {
    for (int x = 1; x + 1 < kSize; ++x) {
      if (!(clean.depth.at(x, y) > 0 && m.depth.at(x, y) == 0)) continue;
      clustered += m.depth.at(x + 1, y) == 0 || m.depth.at(x - 1, y) == 0 ||
                   m.depth.at(x, y + 1) == 0 || m.depth.at(x, y - 1) == 0;
    }
  }
  std::printf("holes=0.05: %d of 10000 object pixels without depth, %.1f %% of them clustered\n",
              missing, 100.0 * clustered / missing);
  EXPECT_GT(clustered, 0.9 * missing);

  Maps o = clean;
  Apply(Parse("outliers=0.01,mask=depth"), o);
  int moved = 0;
  for (size_t p = 0; p < o.depth.pixel_count(); ++p) {
    if (clean.depth.data()[p] == 0) continue;
    const float z = o.depth.data()[p];
    EXPECT_TRUE(z >= 0.5f && z <= 10.0f) << z;  // inside the clip range
    moved += z != 2.0f;
  }
  std::printf("outliers=0.01: %d of 10000 object pixels moved\n", moved);
  EXPECT_GE(moved, 90);  // 100 drawn, a few twice or at 2 itself
  EXPECT_LE(moved, 100);
  for (size_t p = 0; p < o.depth.pixel_count(); ++p)
    EXPECT_EQ(o.mask.data()[p] == 255, o.depth.data()[p] > 0);
}

TEST(SensorModel, SameSeedSameMapsEveryViewItsOwnStream) {
  const SensorModel model = Parse("sigma=0.01,holes=0.02,outliers=0.001,flying=0.5");
  Maps a = Square(2.0f, 60), b = Square(2.0f, 60), c = Square(2.0f, 60), d = Square(2.0f, 60);
  Apply(model, a, 0);
  Apply(model, b, 0);
  Apply(model, c, 1);
  Apply(Parse("sigma=0.01,holes=0.02,outliers=0.001,flying=0.5,seed=2"), d, 0);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_NE(a.depth, c.depth);
  EXPECT_NE(a.depth, d.depth);
}

TEST(SensorModel, DatasetManifestCarriesTheModel) {
  Dataset d;
  d.cameras.emplace(1, Pinhole());
  d.views.push_back({"a", 1, kIdentity, "color/a.png", "depth/a.exr", "mask/a.png", ""});
  d.depth_noise = Parse("sigma=0.3%,model=quadratic,holes=0.02,edge=1,seed=3");
  std::stringstream s;
  WriteManifest(s, d);
  EXPECT_NE(s.str().find("\"noise\""), std::string::npos) << s.str();
  EXPECT_EQ(ReadManifest(s, "mem"), d);
  std::stringstream bad(
      R"({"format": "ibr-dataset", "version": 1, "depth": {"noise": {"holes": 3}},
          "cameras": [], "views": []})");
  EXPECT_THROW(ReadManifest(bad, "bad.json"), core::InputError);
}

}  // namespace
}  // namespace capture
