// libFuzzer target: an `ibr capture --noise` spec (see fuzz_reader.h).
// An accepted model passes its own check and round-trips through the JSON
// that dataset.json records.
#include <nlohmann/json.hpp>
#include <sstream>

#include "capture/sensor_model.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const std::string spec((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const capture::SensorModel m = capture::ParseSensorModel(spec, 2.0, 1.5);
    if (!(capture::SensorModel::FromJson(m.ToJson(), "fuzz") == m)) {
      std::fprintf(stderr, "fuzz: the model does not round-trip through JSON\n");
      std::abort();
    }
  });
}
