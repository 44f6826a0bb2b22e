// json_reader.h: typed, key-path-aware reading of a JSON document for the scene loader.
// Every failure becomes one InputError line "FILE: KEY: what", KEY a dotted path such as
// materials[1].g, so a user can find the offending value without reading a stack trace.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/enum_names.h"
#include "core/input_error.h"
#include "scene/scene.h"

namespace narval::scene_detail {

using json = nlohmann::json;

// What the loader knows of one key it looked up: the scene's schema, learnt as it reads
// (`narval scene --keys`), and the default that fills in a key left out (`--resolved`).
struct KeyRecord {
  std::string type;   // "number", "integer", "boolean", "string", "[3 numbers]", ...; "" not typed here
  std::string range;  // "[0, 1]", ">= 1", the allowed names; "" any
  json fallback;      // the value taken when it is left out; null: required, or no value
  bool required = false;
  const json* given = nullptr;  // the scene's value, if it gives one (valid while the scene is read)
};

// Where messages go while one scene is read.
struct JsonContext {
  std::string file;                      // the scene file's name as the user gave it
  std::vector<std::string>* warnings;    // Scene::warnings
  std::vector<std::string> unknownKeys;  // dotted paths of keys the schema did not ask for
  std::map<std::string, KeyRecord> keys;  // every key looked up, by its dotted path
  bool checkFiles = true;                 // false: volume paths are not looked for (the key table)
  // Unknown keys that are near misses of a key their object asked for: (key, the key it probably
  // meant), both dotted. The loader fails on the first once the whole scene is read.
  std::vector<std::pair<std::string, std::string>> nearMisses;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  void warn(const std::string& key, const std::string& what) const;
  // Whether the scene sets the key (or, for changedUnder, any key below it) away from its default.
  bool changed(const std::string& key) const;
  bool changedUnder(const std::string& key) const;
  // Warns "KEY: what" when the key is changed: a setting that cannot apply is named, while a
  // resolved scene (every default written out) stays quiet.
  void warnIfChanged(const std::string& key, const std::string& what) const;
};

// The whole scene read through `ctx` (scene_load.cpp), which keeps what it learnt of every key.
Scene parseScene(JsonContext& ctx, const std::string& jsonText, const std::vector<std::string>& overrides);

std::string childKey(const std::string& parent, const std::string& name);  // "a" + "b" -> "a.b"
std::string indexKey(const std::string& parent, size_t index);             // "a" + 1 -> "a[1]"
// A key as the scene-format reference names it: indices dropped, "materials[2].g" -> "materials[].g".
std::string schemaKey(const std::string& key);
// An unknown key that is taken for a typo of `name`: a near miss (core/near_miss.h), by case at any length, by one
// edit when the longer of the two has three letters or more ("sp" for "spp"; "x" is not a misspelt
// "g"), or another renderer's word for it ("samples" for "spp", "maxDepth" for "bounces").
bool isTypoOf(const std::string& unknown, const std::string& name);

// A float as the messages print it: the shortest form that reads back (1.5, 0.0001, 1e+20).
std::string formatNumber(float v);
json jsonNumber(float v);  // the same, as a JSON number
json jsonVec3(const Vec3f& v);

// Conversions of one value; `key` names it in messages.
float toFloat(const JsonContext& ctx, const json& v, const std::string& key);         // finite
int64_t toInteger(const JsonContext& ctx, const json& v, const std::string& key);     // integral
bool toBool(const JsonContext& ctx, const json& v, const std::string& key);
std::string toString(const JsonContext& ctx, const json& v, const std::string& key);
Vec3f toVec3(const JsonContext& ctx, const json& v, const std::string& key);          // exactly 3
const json& toArray(const JsonContext& ctx, const json& v, const std::string& key);

// One JSON object being read. Remembers which keys the schema asked for so that reportUnknown()
// can warn about the rest (typos such as "fov" must not pass silently).
class ObjectReader {
 public:
  // Fails with "KEY: expected an object, got T" unless `value` is an object.
  ObjectReader(JsonContext& ctx, const json& value, std::string key);

  const std::string& key() const { return key_; }
  std::string keyOf(const std::string& name) const { return childKey(key_, name); }
  JsonContext& context() const { return ctx_; }

  bool has(const std::string& name) const;
  const json* find(const std::string& name);     // nullptr when absent; marks the key as known
  const json& require(const std::string& name);  // "KEY: missing required key" when absent
  // Records a key's type, default and range (KeyRecord); a field left empty keeps what it holds.
  void note(const std::string& name, const std::string& type, const json& fallback, const std::string& range = "");
  void noteRange(const std::string& name, const std::string& range);

  float getFloat(const std::string& name, float fallback);
  float requireFloat(const std::string& name);
  int64_t getInteger(const std::string& name, int64_t fallback);
  bool getBool(const std::string& name, bool fallback);
  std::string getString(const std::string& name, const std::string& fallback);
  std::string requireString(const std::string& name);
  Vec3f getVec3(const std::string& name, const Vec3f& fallback);
  Vec3f requireVec3(const std::string& name);

  // Adds "FILE: unknown key KEY (ignored)" for every key never looked up, or, for one that is a
  // near miss of a key this object asked for ("sPP" for "spp"), records it in nearMisses: a typo
  // that would otherwise run the default silently, perhaps a thousand times the work.
  void reportUnknown();

 private:
  std::string nearMissOf(const std::string& unknown) const;  // the asked-for key it misses, or ""

  JsonContext& ctx_;
  const json& value_;
  std::string key_;
  std::vector<std::string> known_;
};

// An enumeration's value by its name (core/enum_names.h): "KEY: unknown value "x" (allowed: ...)".
template <typename E>
E toEnum(const JsonContext& ctx, const json& v, const std::string& key, const EnumNames<E>& names) {
  const std::string s = toString(ctx, v, key);
  E value;
  if (!enumFromName(names, s, &value)) ctx.fail(key, "unknown value \"" + s + "\" (allowed: " + enumNameList(names) + ")");
  return value;
}

template <typename E>
E readEnum(ObjectReader& r, const std::string& name, const EnumNames<E>& names, E fallback) {
  const json* v = r.find(name);
  r.note(name, "string", enumName(names, fallback), enumNameList(names));
  return v ? toEnum(r.context(), *v, r.keyOf(name), names) : fallback;
}

template <typename E>
E requireEnum(ObjectReader& r, const std::string& name, const EnumNames<E>& names) {
  const json& v = r.require(name);
  r.note(name, "string", nullptr, enumNameList(names));
  return toEnum(r.context(), v, r.keyOf(name), names);
}

// Range checks: the message names the value as the user wrote it.
constexpr int64_t kIntMax = std::numeric_limits<int>::max();
void checkNonNegative(const JsonContext& ctx, const std::string& key, float v);
void checkNonNegative(const JsonContext& ctx, const std::string& key, const Vec3f& v);
int64_t checkIntRange(const JsonContext& ctx, const std::string& key, int64_t v, int64_t lo, int64_t hi);
int readInt(ObjectReader& r, const std::string& name, int fallback, int64_t lo, int64_t hi = kIntMax);
float readNonNegative(ObjectReader& r, const std::string& name, float fallback);
float readUnitInterval(ObjectReader& r, const std::string& name, float fallback);
// "[lo, hi]", as the messages and the key table write a closed range.
std::string closedRange(float lo, float hi);
// A number in [lo, hi]: "KEY: must be in [lo, hi], got x" otherwise.
float readInRange(ObjectReader& r, const std::string& name, float fallback, float lo, float hi);

}  // namespace narval::scene_detail
