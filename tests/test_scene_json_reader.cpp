// The scene loader's JSON reader (host/scene/json_reader.cpp): its fast parser must accept
// exactly what nlohmann-json accepts (minus duplicate keys) and produce the same values, so that
// messages and scenes are what they were with nlohmann-json's parser; a large scene keeps every
// light exactly; duplicate keys and paths are reported at any depth and index.
#include "scene/json_reader.h"
#include "test_scene_util.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <random>
#include <set>

using namespace canopy;
using namespace canopy::detail;
using namespace canopy::test;

namespace {

using njson = nlohmann::json;
using Type = Document::Type;

// Same value: types, numbers bit for bit, strings byte for byte, objects as key sets.
::testing::AssertionResult same(const Document& d, uint32_t i, const njson& j) {
  const Document::Node& n = d.node(i);
  auto fail = [&](const char* what) {
    return ::testing::AssertionFailure()
           << what << " differs at " << d.path(i) << ": " << j.dump().substr(0, 80);
  };
  switch (n.type) {
  case Type::null:
    return j.is_null() ? ::testing::AssertionSuccess() : fail("null");
  case Type::boolean:
    return j.is_boolean() && j.get<bool>() == n.b ? ::testing::AssertionSuccess() : fail("bool");
  case Type::integer:
    return j.is_number_integer() && !j.is_number_unsigned() && j.get<int64_t>() == n.i
               ? ::testing::AssertionSuccess()
               : fail("integer");
  case Type::unsigned_integer:
    return j.is_number_unsigned() && j.get<uint64_t>() == n.u ? ::testing::AssertionSuccess()
                                                              : fail("unsigned");
  case Type::floating: {
    if (!j.is_number_float()) return fail("float type");
    double a = j.get<double>(), b = n.f;
    return std::memcmp(&a, &b, sizeof a) == 0 ? ::testing::AssertionSuccess() : fail("float");
  }
  case Type::string:
    return j.is_string() && j.get<std::string>() == d.str(n) ? ::testing::AssertionSuccess()
                                                             : fail("string");
  case Type::array:
    if (!j.is_array() || j.size() != n.n) return fail("array");
    for (uint32_t k = 0; k < n.n; ++k)
      if (auto r = same(d, n.first + k, j[k]); !r) return r;
    return ::testing::AssertionSuccess();
  case Type::object:
    if (!j.is_object() || j.size() != n.n) return fail("object");
    for (uint32_t m = 0; m < n.n; ++m) {
      auto it = j.find(std::string(d.str(d.node(n.first + 2 * m))));
      if (it == j.end()) return fail("key");
      if (auto r = same(d, n.first + 2 * m + 1, *it); !r) return r;
    }
    return ::testing::AssertionSuccess();
  }
  return fail("type");
}

// True if nlohmann-json (with comments) accepts `text` and no object repeats a key.
bool nlohmann_accepts(const std::string& text, njson& out) {
  bool dup = false;
  std::vector<std::set<std::string>> keys;
  try {
    out = njson::parse(
        text,
        [&](int, njson::parse_event_t ev, njson& v) {
          if (ev == njson::parse_event_t::object_start) keys.emplace_back();
          if (ev == njson::parse_event_t::object_end) keys.pop_back();
          if (ev == njson::parse_event_t::key && !keys.back().insert(v.get<std::string>()).second)
            dup = true;
          return true;
        },
        true, /*ignore_comments=*/true);
  } catch (const njson::exception&) {
    return false;
  }
  return !dup;
}

void expect_agreement(const std::string& text) {
  njson j;
  bool ref = nlohmann_accepts(text, j);
  Document d;
  bool fast = fast_parse_json(text, d);
  ASSERT_EQ(fast, ref) << "text: " << text;
  if (fast) {
    EXPECT_TRUE(same(d, d.root, j)) << "text: " << text;
  }
}

const char* kTricky[] = {
    "{}",
    "[]",
    "0",
    "-0",
    "-0.0",
    "1e5",
    "1E+5",
    "1e-5",
    "0.5e1",
    "-12.5E-3",
    "1e-400",
    "4.9e-324",
    "2.2250738585072011e-308",
    "1.7976931348623157e308",
    "1e309",
    "-1e999",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775808",
    "-9223372036854775809",
    "01",
    "1.",
    ".5",
    "-",
    "+1",
    "1e",
    "1e+",
    "0x10",
    "NaN",
    "Infinity",
    "true",
    "false",
    "null",
    "tru",
    "nul",
    "truex",
    "\"\"",
    "\"a\\\"b\"",
    "\"\\u0000\"",
    "\"\\ud83d\\ude00\"",
    "\"\\ud83d\"",
    "\"\\ude00\"",
    "\"\\ud83dx\"",
    "\"\\u12\"",
    "\"\\x\"",
    "\"\t\"",
    "\"\x7f\"",
    "\"\xc3\xa9\"",
    "\"\xc3\"",
    "\"\xe2\x80\xa8\"",
    "\"\xed\xa0\x80\"",
    "\"\xf0\x9f\x98\x80\"",
    "\"\xf4\x90\x80\x80\"",
    "\"\xc0\xaf\"",
    "\"\xff\"",
    "\xef\xbb\xbf{}",
    "\xef\xbb{}",
    "{} ",
    " {}\n",
    "{}x",
    "{} {}",
    "[1,]",
    "[,1]",
    "[1 2]",
    "{\"a\":1,}",
    "{\"a\" 1}",
    "{\"a\":}",
    "{1:2}",
    "{\"a\":1,\"a\":2}",
    "{\"a\":{\"b\":1,\"b\":1}}",
    "[{\"a\":1},{\"a\":1}]",
    "// c\n{}",
    "{} // c",
    "{}//",
    "/* c */ {}",
    "{/* c */}",
    "{} /* c",
    "{} /",
    "{} /x",
    "[1/*x*/,2]",
    "{\"a\"/**/:/**/1}",
    "[1,// c\r2]",
    "[[[[[[[[[[]]]]]]]]]]",
    "[[[[[[[[[[]]]]]]]]]",
    "{\"k\": [1, 2.5, \"s\", true, false, null, {}, []]}",
    "",
    "   ",
    "\"unterminated",
    "[\"a\\/b\\b\\f\\n\\r\\t\"]",
};

} // namespace

TEST(JsonReader, FastParserAgreesOnTrickyInputs) {
  for (const char* t : kTricky)
    expect_agreement(t);
  // Objects large enough for the sorted duplicate check.
  std::string big = "{", dup = "{";
  for (int k = 0; k < 40; ++k) {
    big += fmt::format("{}\"k{}\": {}", k ? ", " : "", k, k);
    dup += fmt::format("{}\"k{}\": {}", k ? ", " : "", k % 39, k);
  }
  expect_agreement(big + "}");
  expect_agreement(dup + "}");
}

// Random byte-level mutants of a scene (fixed seed): whatever the fast parser accepts, nlohmann-
// json accepts with the same values, and the other way round.
TEST(JsonReader, FastParserAgreesOnMutants) {
  const std::string base = R"({
  // a comment
  "camera": {"position": [0, 1.5, 6], "look_at": [0, 1, 0], "fov": 45},
  "film": {"width": 64, "height": 48}, /* another */
  "materials": [{"name": "m\u00e9\n", "albedo": [0.5, 0.25e0, 1E-1]}],
  "lights": [{"type": "point", "position": [-1, 2.0, 3], "intensity": 18446744073709551615},
             {"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0], "cone_angle": 30,
              "intensity": [1, 2, 3], "on": true, "off": false, "none": null, "s": "\ud83d\ude00"}]
})";
  const char alphabet[] = "{}[],:\"\\/*-+.0123456789eEtrufalsn \n\t\x01\x7f\xc3\xa9\xed\xff";
  std::mt19937 rng(12345);
  for (int m = 0; m < 4000; ++m) {
    std::string t = base;
    int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      size_t pos = rng() % (t.size() + 1);
      char c = alphabet[rng() % (sizeof(alphabet) - 1)];
      switch (rng() % 4) {
      case 0:
        if (pos < t.size()) t[pos] = c;
        break;
      case 1:
        t.insert(t.begin() + long(pos), c);
        break;
      case 2:
        if (pos < t.size()) t.erase(pos, 1 + rng() % 3);
        break;
      default:
        t.resize(pos);
        break;
      }
    }
    expect_agreement(t);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

// 2*10^4 point lights with full float precision: every position and intensity is loaded exactly.
TEST(JsonReader, ManyLightsRoundTripExactly) {
  const int n = 20000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> v(size_t(n) * 4);
  std::string lights = "[";
  for (int i = 0; i < n; ++i) {
    float* x = &v[size_t(i) * 4];
    for (int k = 0; k < 4; ++k)
      x[k] = k == 3 ? std::ldexp(std::fabs(u(rng)) + 1e-3f, -int(rng() % 20)) : u(rng) * 100.0f;
    lights += fmt::format("{}{{\"type\": \"point\", \"position\": [{:.9g}, {:.9g}, {:.9g}], "
                          "\"intensity\": {:.9g}}}",
                          i ? ",\n" : "", x[0], x[1], x[2], x[3]);
  }
  // The camera at 0 makes the scene origin 0: positions are stored as parsed, not rebased.
  Scene s = load_str(R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "lights": )" +
                     lights + "]}");
  ASSERT_EQ(s.origin.x, 0.0);
  ASSERT_EQ(s.lights.size(), size_t(n));
  for (int i = 0; i < n; ++i) {
    const float* x = &v[size_t(i) * 4];
    const Light& l = s.lights[size_t(i)];
    ASSERT_EQ(l.type, LIGHT_POINT) << i;
    ASSERT_EQ(l.p.x, x[0]) << i;
    ASSERT_EQ(l.p.y, x[1]) << i;
    ASSERT_EQ(l.p.z, x[2]) << i;
    ASSERT_EQ(l.emission.x, x[3]) << i;
    ASSERT_EQ(l.emission.y, x[3]) << i;
    ASSERT_EQ(l.emission.z, x[3]) << i;
  }
}

namespace {
// `count` point lights; light `bad` gets `extra` appended to its members.
std::string lights_with(int count, int bad, const std::string& extra) {
  std::string s = "[";
  for (int i = 0; i < count; ++i)
    s += fmt::format("{}{{\"type\": \"point\", \"position\": [0, 2, 0], \"intensity\": 1{}}}",
                     i ? ", " : "", i == bad ? extra : "");
  return s + "]";
}
} // namespace

TEST(JsonReader, DuplicateKeyReportedAtAnyDepthAndIndex) {
  EXPECT_EQ(error_of(scene_with("", lights_with(5000, 4321, R"(, "type": "spot")"))),
            "scene.json: lights[4321].type: duplicate key");
  EXPECT_EQ(error_of(scene_with(R"("film": {"width": 8}, "film": {"width": 8})")),
            "scene.json: film: duplicate key");
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{}, {"type": "grid", "light": {"type": "point",
            "intensity": 1, "intensity": 2}}])")),
            "scene.json: light_sets[1].light.intensity: duplicate key");
  // Before any later syntax error, as with nlohmann-json's parser.
  EXPECT_EQ(error_of(scene_with("", lights_with(3000, 2999, R"(, "type": "spot")")) + " x"),
            "scene.json: lights[2999].type: duplicate key");
}

TEST(JsonReader, PathsOfLateAndDeepValues) {
  EXPECT_EQ(error_of(scene_with("", lights_with(5000, 4999, R"(, "radius": 1)"))),
            "scene.json: lights[4999].radius: unknown key");
  EXPECT_EQ(error_of(scene_with("", lights_with(3000, 1234, R"(, "a\u0009b": 1, "A": 2)"))),
            "scene.json: lights[1234].A: unknown key");
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "grid", "count": 4,
            "origin": [0, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1],
            "light": {"type": "point", "position": [0, 0, "x"], "intensity": 1}}])")),
            "scene.json: light_sets[0].light.position[2]: must be a number");
}
