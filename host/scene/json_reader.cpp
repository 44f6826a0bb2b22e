// json_reader.cpp: see json_reader.h.
#include "scene/json_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "core/near_miss.h"
#include "core/number_format.h"

namespace narval::scene_detail {

void JsonContext::fail(const std::string& key, const std::string& what) const {
  throw inputError(file, key, what);
}

void JsonContext::warn(const std::string& key, const std::string& what) const {
  warnings->push_back(inputError(file, key, what).what());
}

bool JsonContext::changed(const std::string& key) const {
  const auto it = keys.find(key);
  if (it == keys.end() || !it->second.given) return false;
  // JSON compares 4 and 4.0 as equal numbers. A key with no default (an object) is changed by its keys.
  return !it->second.fallback.is_null() && *it->second.given != it->second.fallback;
}

bool JsonContext::changedUnder(const std::string& key) const {
  for (auto it = keys.lower_bound(key + "."); it != keys.end() && it->first.rfind(key + ".", 0) == 0; ++it)
    if (changed(it->first)) return true;
  return false;
}

void JsonContext::warnIfChanged(const std::string& key, const std::string& what) const {
  if (changed(key)) warn(key, what);
}

std::string childKey(const std::string& parent, const std::string& name) {
  return parent.empty() ? name : parent + "." + name;
}

std::string indexKey(const std::string& parent, size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

std::string schemaKey(const std::string& key) {
  std::string out;
  bool inIndex = false;
  for (char c : key) {
    if (c == ']') inIndex = false;
    if (!inIndex) out += c;
    if (c == '[') inIndex = true;
  }
  return out;
}

// Other renderers' and papers' words for narval's keys (lower case): taken for the key as a typo is.
const std::pair<const char*, const char*> kSynonyms[] = {
    {"samples", "spp"},        {"samplesperpixel", "spp"}, {"maxdepth", "bounces"},   {"maxbounces", "bounces"},
    {"depth", "bounces"},      {"phase", "phaseFunction"}, {"anisotropy", "g"},
    {"sigma_s", "scattering"}, {"sigma_a", "absorption"},  {"filename", "path"},
    {"file", "path"},          {"target", "lookAt"},       {"look_at", "lookAt"},     {"tonemap", "toneMapping"}};

bool isTypoOf(const std::string& unknown, const std::string& name) {
  if (unknown == name) return false;
  for (const auto& [word, key] : kSynonyms)
    if (lowercase(unknown) == word && name == key) return true;
  return nearMiss(unknown, name) &&
         (std::max(unknown.size(), name.size()) >= 3 || lowercase(unknown) == lowercase(name));
}

std::string formatNumber(float v) {
  // Whole numbers as written (180, not 1.8e+02); others in the fewest digits that read back.
  if (v == std::floor(v) && std::fabs(v) < 1e9f) return std::to_string(static_cast<long long>(v));
  return formatShortest(v);
}

json jsonNumber(float v) { return json::parse(formatNumber(v)); }

json jsonVec3(const Vec3f& v) { return json::array({jsonNumber(v[0]), jsonNumber(v[1]), jsonNumber(v[2])}); }

namespace {

std::string got(const json& v) { return std::string("got ") + v.type_name(); }

}  // namespace

float toFloat(const JsonContext& ctx, const json& v, const std::string& key) {
  if (!v.is_number()) ctx.fail(key, "expected a number, " + got(v));
  const float f = static_cast<float>(v.get<double>());
  // JSON itself cannot say NaN or inf, but 1e39 overflows the renderer's floats.
  if (!std::isfinite(f)) ctx.fail(key, "must be finite as a 32-bit float, got " + v.dump());
  return f;
}

int64_t toInteger(const JsonContext& ctx, const json& v, const std::string& key) {
  if (v.is_number_unsigned()) {
    if (v.get<uint64_t>() > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()))
      ctx.fail(key, "integer out of range, got " + v.dump());
    return static_cast<int64_t>(v.get<uint64_t>());
  }
  if (v.is_number_integer()) return v.get<int64_t>();
  if (v.is_number_float()) {
    // 16.0 is an integer to a user; 16.5 is not.
    const double d = v.get<double>();
    if (d != std::floor(d)) ctx.fail(key, "expected an integer, got " + v.dump());
    if (std::fabs(d) >= 9.2e18) ctx.fail(key, "integer out of range, got " + v.dump());
    return static_cast<int64_t>(d);
  }
  ctx.fail(key, "expected an integer, " + got(v));
}

bool toBool(const JsonContext& ctx, const json& v, const std::string& key) {
  if (!v.is_boolean()) ctx.fail(key, "expected a boolean, " + got(v));
  return v.get<bool>();
}

std::string toString(const JsonContext& ctx, const json& v, const std::string& key) {
  if (!v.is_string()) ctx.fail(key, "expected a string, " + got(v));
  return v.get<std::string>();
}

Vec3f toVec3(const JsonContext& ctx, const json& v, const std::string& key) {
  if (!v.is_array()) ctx.fail(key, "expected an array of 3 numbers, " + got(v));
  if (v.size() != 3)
    ctx.fail(key, "expected an array of 3 numbers, got " + std::to_string(v.size()) + " elements");
  Vec3f out;
  for (size_t i = 0; i < 3; ++i) out[i] = toFloat(ctx, v[i], indexKey(key, i));
  return out;
}

const json& toArray(const JsonContext& ctx, const json& v, const std::string& key) {
  if (!v.is_array()) ctx.fail(key, "expected an array, " + got(v));
  return v;
}

ObjectReader::ObjectReader(JsonContext& ctx, const json& value, std::string key)
    : ctx_(ctx), value_(value), key_(std::move(key)) {
  if (!value_.is_object()) ctx_.fail(key_, "expected an object, " + got(value_));
}

bool ObjectReader::has(const std::string& name) const { return value_.contains(name); }

const json* ObjectReader::find(const std::string& name) {
  known_.push_back(name);
  const auto it = value_.find(name);
  const json* v = it == value_.end() ? nullptr : &*it;
  ctx_.keys[keyOf(name)].given = v;
  return v;
}

void ObjectReader::note(const std::string& name, const std::string& type, const json& fallback,
                        const std::string& range) {
  KeyRecord& k = ctx_.keys[keyOf(name)];
  if (!type.empty()) k.type = type;
  if (!fallback.is_null()) k.fallback = fallback;
  if (!range.empty()) k.range = range;
}

void ObjectReader::noteRange(const std::string& name, const std::string& range) { note(name, "", nullptr, range); }

const json& ObjectReader::require(const std::string& name) {
  const json* v = find(name);
  ctx_.keys[keyOf(name)].required = true;
  if (!v) {
    for (const auto& item : value_.items())
      if (isTypoOf(item.key(), name))
        ctx_.fail(keyOf(name), "missing required key (is \"" + item.key() + "\" meant to be it?)");
    ctx_.fail(keyOf(name), "missing required key");
  }
  return *v;
}

std::string ObjectReader::nearMissOf(const std::string& unknown) const {
  for (const std::string& name : known_)
    if (isTypoOf(unknown, name)) return name;
  return "";
}

float ObjectReader::getFloat(const std::string& name, float fallback) {
  const json* v = find(name);
  note(name, "number", jsonNumber(fallback));
  return v ? toFloat(ctx_, *v, keyOf(name)) : fallback;
}

float ObjectReader::requireFloat(const std::string& name) {
  const json& v = require(name);
  note(name, "number", nullptr);
  return toFloat(ctx_, v, keyOf(name));
}

int64_t ObjectReader::getInteger(const std::string& name, int64_t fallback) {
  const json* v = find(name);
  note(name, "integer", fallback);
  return v ? toInteger(ctx_, *v, keyOf(name)) : fallback;
}

bool ObjectReader::getBool(const std::string& name, bool fallback) {
  const json* v = find(name);
  note(name, "boolean", fallback);
  return v ? toBool(ctx_, *v, keyOf(name)) : fallback;
}

std::string ObjectReader::getString(const std::string& name, const std::string& fallback) {
  const json* v = find(name);
  note(name, "string", fallback);
  return v ? toString(ctx_, *v, keyOf(name)) : fallback;
}

std::string ObjectReader::requireString(const std::string& name) {
  const json& v = require(name);
  note(name, "string", nullptr);
  return toString(ctx_, v, keyOf(name));
}

Vec3f ObjectReader::getVec3(const std::string& name, const Vec3f& fallback) {
  const json* v = find(name);
  note(name, "[3 numbers]", jsonVec3(fallback));
  return v ? toVec3(ctx_, *v, keyOf(name)) : fallback;
}

Vec3f ObjectReader::requireVec3(const std::string& name) {
  const json& v = require(name);
  note(name, "[3 numbers]", nullptr);
  return toVec3(ctx_, v, keyOf(name));
}

void ObjectReader::reportUnknown() {
  for (const auto& item : value_.items()) {
    if (std::find(known_.begin(), known_.end(), item.key()) != known_.end()) continue;
    const std::string key = keyOf(item.key());
    ctx_.unknownKeys.push_back(key);
    const std::string meant = nearMissOf(item.key());
    if (meant.empty())
      ctx_.warnings->push_back(ctx_.file + ": unknown key " + key + " (ignored)");
    else
      ctx_.nearMisses.emplace_back(key, keyOf(meant));
  }
}

void checkNonNegative(const JsonContext& ctx, const std::string& key, float v) {
  if (!(v >= 0)) ctx.fail(key, "must be non-negative, got " + formatNumber(v));
}

void checkNonNegative(const JsonContext& ctx, const std::string& key, const Vec3f& v) {
  for (size_t i = 0; i < 3; ++i) checkNonNegative(ctx, indexKey(key, i), v[i]);
}

int64_t checkIntRange(const JsonContext& ctx, const std::string& key, int64_t v, int64_t lo, int64_t hi) {
  if (v < lo) ctx.fail(key, "must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
  if (v > hi) ctx.fail(key, "must be at most " + std::to_string(hi) + ", got " + std::to_string(v));
  return v;
}

int readInt(ObjectReader& r, const std::string& name, int fallback, int64_t lo, int64_t hi) {
  r.noteRange(name,
              hi == kIntMax ? ">= " + std::to_string(lo) : "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(checkIntRange(r.context(), r.keyOf(name), r.getInteger(name, fallback), lo, hi));
}

float readNonNegative(ObjectReader& r, const std::string& name, float fallback) {
  const float v = r.getFloat(name, fallback);
  r.noteRange(name, ">= 0");
  checkNonNegative(r.context(), r.keyOf(name), v);
  return v;
}

float readUnitInterval(ObjectReader& r, const std::string& name, float fallback) {
  return readInRange(r, name, fallback, 0, 1);
}

std::string closedRange(float lo, float hi) { return "[" + formatNumber(lo) + ", " + formatNumber(hi) + "]"; }

float readInRange(ObjectReader& r, const std::string& name, float fallback, float lo, float hi) {
  const float v = r.getFloat(name, fallback);
  r.noteRange(name, closedRange(lo, hi));
  if (!(v >= lo && v <= hi))
    r.context().fail(r.keyOf(name), "must be in " + closedRange(lo, hi) + ", got " + formatNumber(v));
  return v;
}

}  // namespace narval::scene_detail
