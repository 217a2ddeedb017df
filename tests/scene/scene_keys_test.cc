// The scene keys' one table: the reader accepts exactly its keys, and the
// scene-format guide shows exactly its text.
#include "scene/scene_keys.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.h"

namespace scene {
namespace {

std::string Trimmed(const std::string& s) {
  const size_t a = s.find_first_not_of(" \n");
  const size_t b = s.find_last_not_of(" \n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

TEST(SceneKeys, TheGuideShowsTheReadersTable) {
  const char* source = std::getenv("IBR_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "IBR_SOURCE_DIR (set by ctest) names the checkout";
  const std::string path = std::string(source) + "/docs/guide/scene-format.md";
  std::ifstream in(path);
  ASSERT_TRUE(in) << "cannot open " << path;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string guide = ss.str();
  const std::string begin = "<!-- BEGIN GENERATED KEY TABLE -->";
  const std::string end = "<!-- END GENERATED KEY TABLE -->";
  const size_t a = guide.find(begin), b = guide.find(end);
  ASSERT_NE(a, std::string::npos) << path << " lacks " << begin;
  ASSERT_NE(b, std::string::npos) << path << " lacks " << end;
  ASSERT_LT(a, b);
  EXPECT_EQ(Trimmed(guide.substr(a + begin.size(), b - a - begin.size())),
            Trimmed(ObjectKeysMarkdown()))
      << "the guide's key table is stale: replace it with the output of "
         "`build/bin/ibr info --scene-keys`";
}

TEST(SceneKeys, EveryKindIsReadableAndEveryKeyItsOwn) {
  std::set<std::string> names;
  for (const ObjectKindSpec& kind : ObjectKinds()) {
    EXPECT_TRUE(names.insert(std::string(kind.name)).second) << kind.name;
    EXPECT_EQ(FindObjectKind(kind.name), &kind);
    EXPECT_EQ(ObjectTypeName(kind.type), kind.name);
    std::set<std::string_view> keys;
    for (const KeySpec& k : CommonObjectKeys()) keys.insert(k.key);
    for (const KeySpec& k : kind.keys) {
      EXPECT_TRUE(keys.insert(k.key).second) << kind.name << ": key " << k.key << " twice";
      EXPECT_FALSE(k.help.empty()) << kind.name << "." << k.key;
      EXPECT_FALSE(k.type.empty()) << kind.name << "." << k.key;
    }
  }
  EXPECT_EQ(FindObjectKind("teapot"), nullptr);
}

// Each kind's effect keys are taken by the reader; a key of another kind is
// refused with the allowed list.
TEST(SceneKeys, TheReaderTakesTheTablesEffectKeysAndRefusesOthers) {
  for (const ObjectKindSpec& kind : ObjectKinds()) {
    if (kind.name != "volume" && kind.name != "deform" && kind.name != "displaced-mesh") continue;
    std::string object = "{\"type\": \"" + std::string(kind.name) + "\"";
    if (kind.name == "volume") object += ", \"volume\": \"v.dat\"";
    if (kind.name == "deform") object += ", \"mesh\": {\"shape\": \"sphere\"}";
    if (kind.name == "displaced-mesh")
      object += ", \"mesh\": {\"shape\": \"torus\"}, \"height\": {\"generator\": \"bumps\"}";
    for (const KeySpec& k : kind.keys) {
      if (k.effect) {
        object += ", \"" + std::string(k.key) + "\": " + (k.type == "list" ? "[]" : "\"x\"");
      }
    }
    const std::string text =
        "{\"version\": 1, \"cameras\": {\"orbit\": {}}, \"objects\": [" + object + "}]}";
    std::stringstream in(text);
    ReadOptions options;
    options.check_files = false;
    const Scene s = ReadScene(in, "t.json", options);
    ASSERT_EQ(s.objects.size(), 1u);
    for (const KeySpec& k : kind.keys) {
      if (k.effect) {
        EXPECT_TRUE(s.objects[0].settings.Has(std::string(k.key))) << k.key;
      }
    }
    std::stringstream bad("{\"version\": 1, \"cameras\": {\"orbit\": {}}, \"objects\": [" + object +
                          ", \"no_such_key\": 1}]}");
    try {
      ReadScene(bad, "t.json", options);
      FAIL() << kind.name;
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("unknown key 'no_such_key' (allowed here: "),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace scene
