// ibr/volume_object.h values a user types, in the volume's own units: the
// iso value the viewer's slider shows and takes (IsoValueInDataUnits and
// SetIsoValue round trip on a signed 16-bit volume in HU) and window/level.
#include "ibr/volume_object.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.h"

namespace ibr {
namespace {

// An int16 volume spanning -1000..1000 (a CT's air to bone, in HU): its
// texture maps the range to [0, 1], so the normalised scalar differs from
// the value typed.
VolumeObjectData HuVolume() {
  core::Volume v = core::Volume::Zeros({4, 4, 4}, core::ScalarType::kInt16);
  for (int i = 0; i < 64; ++i) v.SetValue(i % 4, (i / 4) % 4, i / 16, -1000 + 2000.0 * i / 63);
  v.FitNormalization();  // as every reader does
  return MakeVolumeObject(std::move(v), core::TransferPreset("ramp"), {}, 8);
}

TEST(VolumeObject, IsoValueRoundTripsInDataUnits) {
  const VolumeObjectData data = HuVolume();
  ASSERT_EQ(data.stats.min, -1000);
  ASSERT_EQ(data.stats.max, 1000);
  VolumeObjectOptions o;
  o.pass.mode = render::VolumeMode::kIso;
  // Typed 300 HU: the pass gets (300 + 1000) / 2000 = 0.65, the slider shows 300.
  SetIsoValue(data, 300, o.pass, "test");
  EXPECT_NEAR(o.pass.iso_value, 0.65, 1e-12);
  o.iso_value = 300;
  EXPECT_EQ(IsoValueInDataUnits(data, o), 300);
  // Only the normalised value known (a mode switched to iso in the viewer):
  // mapped back, 0.25 -> -500 HU.
  o.iso_value.reset();
  o.pass.iso_value = 0.25;
  EXPECT_NEAR(IsoValueInDataUnits(data, o), -500, 1e-9);
  EXPECT_THROW(SetIsoValue(data, 1500, o.pass, "test"), core::InputError);
}

TEST(VolumeObject, WindowLevelIsARampInDataUnits) {
  const VolumeObjectData data = HuVolume();
  const core::TransferFunction tf = WindowLevelTransfer(400, 40, data.stats, "test");
  EXPECT_EQ(tf.units, core::TransferUnits::kData);
  EXPECT_EQ(tf.Evaluate(-160).a, 0);
  EXPECT_NEAR(tf.Evaluate(40).a, 0.5, 1e-6);
  EXPECT_EQ(tf.Evaluate(240).a, 1);
  EXPECT_EQ(tf.Evaluate(900).a, 1);  // above the window: opaque
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [w, l] : {std::pair{0.0, 40.0}, std::pair{-1.0, 40.0}, std::pair{nan, 40.0},
                             std::pair{400.0, nan}, std::pair{100.0, 1100.0}}) {
    EXPECT_THROW(WindowLevelTransfer(w, l, data.stats, "test"), core::InputError) << w << " " << l;
  }
  EXPECT_NO_THROW(WindowLevelTransfer(100, -1100, data.stats, "test"));  // a warning only
}

}  // namespace
}  // namespace ibr
