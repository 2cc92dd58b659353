#include "core/json_document.h"

#include "core/error.h"

#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace pathlab {
namespace {

using Pointer = nlohmann::json::json_pointer;

// The InputError message for `text`, or "(no error)".
std::string error_of(std::string_view text) {
  try {
    (void)JsonDocument::parse(text, "scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string with_crlf(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

void expect_at(const JsonDocument& doc, const std::string& pointer, int line, int column) {
  const SourcePosition p = doc.position(Pointer(pointer));
  EXPECT_EQ(p.line, line) << "pointer '" << pointer << "'";
  EXPECT_EQ(p.column, column) << "pointer '" << pointer << "'";
}

constexpr std::string_view kScene = R"({
  "camera": {
    "fov": 40,
    "position": [0, 1, 5]
  },
  "shapes": [
    {"type": "sphere", "material": "red"},
    {
      "type": "mesh"
    }
  ]
}
)";

TEST(JsonDocumentPositions, NestedKeysAndArrayElements) {
  for (const std::string& text : {std::string(kScene), with_crlf(kScene)}) {
    SCOPED_TRACE(text.find('\r') == std::string::npos ? "LF" : "CRLF");
    const JsonDocument doc = JsonDocument::parse(text, "scene.json");
    EXPECT_EQ(doc.root()["camera"]["fov"], 40);
    expect_at(doc, "", 1, 1);
    expect_at(doc, "/camera", 2, 3);
    expect_at(doc, "/camera/fov", 3, 5);
    expect_at(doc, "/camera/position", 4, 5);
    expect_at(doc, "/camera/position/0", 4, 18);
    expect_at(doc, "/camera/position/2", 4, 24);
    expect_at(doc, "/shapes", 6, 3);
    expect_at(doc, "/shapes/0", 7, 5);
    expect_at(doc, "/shapes/0/type", 7, 6);
    expect_at(doc, "/shapes/0/material", 7, 24);
    expect_at(doc, "/shapes/1", 8, 5);
    expect_at(doc, "/shapes/1/type", 9, 7);
  }
}

TEST(JsonDocumentPositions, WhereAndUnknownPointers) {
  const JsonDocument doc = JsonDocument::parse(kScene, "scenes/box.json");
  EXPECT_EQ(doc.where(Pointer("/camera/fov")), "scenes/box.json:3:5");
  EXPECT_EQ(doc.where(Pointer("/camera/missing")), "scenes/box.json");
  EXPECT_EQ(doc.where(Pointer("/shapes/2")), "scenes/box.json");
  const SourcePosition unknown = doc.position(Pointer("/nope"));
  EXPECT_EQ(unknown.line, 0);
  EXPECT_EQ(unknown.column, 0);
  EXPECT_EQ(doc.file(), std::filesystem::path("scenes/box.json"));
}

TEST(JsonDocumentPositions, RootAfterLeadingWhitespaceAndBom) {
  expect_at(JsonDocument::parse("\n\n  [1, 2]", "s.json"), "", 3, 3);
  expect_at(JsonDocument::parse("\n\n  [1, 2]", "s.json"), "/1", 3, 7);
  expect_at(JsonDocument::parse("7", "s.json"), "", 1, 1);
  // Columns are bytes, so the 3-byte UTF-8 BOM counts.
  const JsonDocument bom = JsonDocument::parse("\xEF\xBB\xBF{\"a\": 1}", "s.json");
  EXPECT_EQ(bom.root()["a"], 1);
  expect_at(bom, "/a", 1, 5);
}

TEST(JsonDocumentPositions, KeysWithEscapesSlashAndTilde) {
  const std::string text = R"({
  "a/b": 1,
  "m~n": {"x\"y": 2},
  "\u00e9t\u00e9": 3,
  "back\\slash": [null, false],
  "\ud83d\ude00": 0
})";
  const JsonDocument doc = JsonDocument::parse(text, "k.json");
  expect_at(doc, "/a~1b", 2, 3);
  expect_at(doc, "/m~0n", 3, 3);
  expect_at(doc, "/m~0n/x\"y", 3, 11);
  expect_at(doc, "/\xC3\xA9t\xC3\xA9", 4, 3);
  expect_at(doc, "/back\\slash/1", 5, 25);
  expect_at(doc, "/\xF0\x9F\x98\x80", 6, 3);
  // The pointers we record are the ones nlohmann itself understands.
  EXPECT_EQ(doc.root().at(Pointer("/m~0n/x\"y")), 2);
  EXPECT_EQ(doc.root().at(Pointer("/a~1b")), 1);
}

TEST(JsonDocumentErrors, MissingComma) {
  // nlohmann reports the last byte of the offending token: the closing quote of "b".
  EXPECT_EQ(error_of("{\n  \"a\": 1\n  \"b\": 2\n}\n"),
            "scene.json:3:5: malformed JSON: unexpected string literal; expected '}'");
  EXPECT_EQ(error_of("[1 2]"), "scene.json:1:4: malformed JSON: unexpected number literal; expected ']'");
}

TEST(JsonDocumentErrors, TrailingComma) {
  EXPECT_EQ(error_of("{\n  \"a\": 1,\n}\n"),
            "scene.json:3:1: malformed JSON: unexpected '}'; expected string literal");
  EXPECT_EQ(error_of("[1, 2,]"),
            "scene.json:1:7: malformed JSON: unexpected ']'; expected '[', '{', or a literal");
}

TEST(JsonDocumentErrors, UnterminatedString) {
  EXPECT_EQ(error_of("{\"name\": \"abc"),
            "scene.json:1:14: malformed JSON: invalid string: missing closing quote");
  EXPECT_EQ(error_of("{\"name\": \"abc\n}"),
            "scene.json:1:14: malformed JSON: invalid string: control character U+000A (LF) "
            "must be escaped to \\u000A or \\n");
}

TEST(JsonDocumentErrors, TruncatedFile) {
  EXPECT_EQ(error_of("{\n  \"a\": [1, 2\n"),
            "scene.json:3:1: malformed JSON: unexpected end of input; expected ']'");
  EXPECT_EQ(error_of(with_crlf("{\n  \"a\": [1, 2")),
            "scene.json:2:13: malformed JSON: unexpected end of input; expected ']'");
}

TEST(JsonDocumentErrors, EmptyInput) {
  EXPECT_EQ(error_of(""),
            "scene.json:1:1: malformed JSON: unexpected end of input; expected '[', '{', or a literal");
  EXPECT_EQ(error_of("\n\n"),
            "scene.json:3:1: malformed JSON: unexpected end of input; expected '[', '{', or a literal");
}

TEST(JsonDocumentErrors, GarbageAtTheEnd) {
  EXPECT_EQ(error_of("{\"a\": 1}\n  x"),
            "scene.json:2:3: malformed JSON: invalid literal; expected end of input");
  EXPECT_EQ(error_of("{\"a\": 1}}"),
            "scene.json:1:9: malformed JSON: unexpected '}'; expected end of input");
  // nlohmann stops at a NUL byte as if the input ended there; we do not.
  EXPECT_EQ(error_of(std::string_view("[1]\0x", 5)), "scene.json:1:4: malformed JSON: unexpected NUL byte");
}

TEST(JsonDocumentErrors, CommentsAreRejected) {
  EXPECT_EQ(error_of("// camera\n{}"), "scene.json:1:1: malformed JSON: invalid literal");
}

// nlohmann reports a number beyond the double range as out_of_range, not as
// a parse error; it is still malformed JSON at the number's position.
TEST(JsonDocumentErrors, OverflowingNumber) {
  EXPECT_EQ(error_of("{\"a\": [1,\n  1e999]}"),
            "scene.json:2:3: malformed JSON: number '1e999' is out of range (numbers must be finite)");
  // The same characters inside a string do not count.
  EXPECT_EQ(error_of("{\"1e999\": \"x 1e999 \\\" -2e400\",\n\"b\": [0, -2e400]}"),
            "scene.json:2:10: malformed JSON: number '-2e400' is out of range (numbers must be finite)");
  // An underflow is 0, not an error.
  EXPECT_EQ(error_of("[1e-999]"), "(no error)");
  // A very long number is cut short in the message.
  const std::string digits(400, '9');
  EXPECT_EQ(error_of("[" + digits + "]"), "scene.json:1:2: malformed JSON: number '" + digits.substr(0, 40) +
                                               "...' is out of range (numbers must be finite)");
}

// JSON has no NaN or infinity; writers that emit them get a hint.
TEST(JsonDocumentErrors, NanAndInfinityLiterals) {
  for (const std::string token : {"NaN", "nan", "NAN", "Infinity", "inf", "INF", "-Infinity", "-inf", "+inf"}) {
    SCOPED_TRACE(token);
    const std::string message = error_of("{\"a\": [1, " + token + "]}");
    EXPECT_EQ(message.rfind("scene.json:1:", 0), 0u) << message;
    EXPECT_NE(message.find(": malformed JSON: "), std::string::npos) << message;
    EXPECT_TRUE(message.ends_with(" (JSON has no NaN or infinity)")) << message;
  }
  EXPECT_EQ(error_of("[1, NaN]"), "scene.json:1:5: malformed JSON: invalid literal (JSON has no NaN or infinity)");
  EXPECT_EQ(error_of("[1,\n  nan]"), "scene.json:2:3: malformed JSON: invalid literal (JSON has no NaN or infinity)");
  // Other bad literals get no hint.
  for (const std::string token : {"nope", "Nano", "infinite", "none", "tru"}) {
    SCOPED_TRACE(token);
    const std::string message = error_of("[" + token + "]");
    EXPECT_NE(message.find("malformed JSON"), std::string::npos) << message;
    EXPECT_EQ(message.find("NaN or infinity"), std::string::npos) << message;
  }
}

TEST(JsonDocumentErrors, DuplicateKeyNamesBothLines) {
  const std::string text = R"({
  "materials": {
    "red": {
      "albedo": [1, 0, 0],
      "roughness": 0.5,
      "albedo": [0, 1, 0]
    }
  }
})";
  EXPECT_EQ(error_of(text), "scene.json:6:7: duplicate key 'albedo' (first at line 4)");
  EXPECT_EQ(error_of(with_crlf(text)), "scene.json:6:7: duplicate key 'albedo' (first at line 4)");
  // Keys are compared after unescaping.
  EXPECT_EQ(error_of(R"({"a": 1, "\u0061": 2})"), "scene.json:1:10: duplicate key 'a' (first at line 1)");
  // The same key in different objects is fine.
  EXPECT_EQ(error_of(R"({"a": {"x": 1}, "b": {"x": 2}, "c": [{"x": 3}, {"x": 4}]})"), "(no error)");
}

TEST(JsonDocumentErrors, TooDeeplyNested) {
  const std::string text = std::string(5000, '[') + std::string(5000, ']');
  EXPECT_NE(error_of(text).find("nested deeper than"), std::string::npos) << error_of(text);
  EXPECT_EQ(error_of(std::string(100, '[') + std::string(100, ']')), "(no error)");
}

class JsonDocumentLoad : public test::TempDirTest {
 protected:

  std::filesystem::path write(const std::string& name, std::string_view content) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

};

TEST_F(JsonDocumentLoad, ReadsFileAndKeepsItsName) {
  const std::filesystem::path path = write("scene.json", with_crlf(kScene));
  const JsonDocument doc = JsonDocument::load(path);
  EXPECT_EQ(doc.file(), path);
  EXPECT_EQ(doc.root()["shapes"][1]["type"], "mesh");
  EXPECT_EQ(doc.where(Pointer("/shapes/1/type")), path.string() + ":9:7");
}

TEST_F(JsonDocumentLoad, MissingFile) {
  const std::filesystem::path path = dir_ / "nope.json";
  try {
    (void)JsonDocument::load(path);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": cannot read scene: No such file or directory");
  }
}

TEST_F(JsonDocumentLoad, DirectoryIsNotAScene) {
  try {
    (void)JsonDocument::load(dir_);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir_.string() + ": cannot read scene: it is a folder, not a regular file");
  }
}

TEST_F(JsonDocumentLoad, EmptyFileIsMalformedAtOneOne) {
  const std::filesystem::path path = write("empty.json", "");
  try {
    (void)JsonDocument::load(path);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ":1:1: malformed JSON: unexpected end of input; expected '[', '{', or a literal");
  }
}

constexpr std::array<std::string_view, 5> kMaterialKeys = {"albedo", "roughness", "emission", "radius", "fov_y"};

TEST(NearestName, TypicalTypos) {
  EXPECT_EQ(nearest_name("albedoo", kMaterialKeys), "albedo");
  EXPECT_EQ(nearest_name("albdo", kMaterialKeys), "albedo");
  EXPECT_EQ(nearest_name("raduis", kMaterialKeys), "radius");     // a swap of neighbours costs 1
  EXPECT_EQ(nearest_name("roughnes", kMaterialKeys), "roughness");
  EXPECT_EQ(nearest_name("Albedo", kMaterialKeys), "albedo");     // case counts, but 1 edit is close
}

// Optimal string alignment: swapping two adjacent letters is one edit, so
// even short keys allow it.
TEST(NearestName, AdjacentTranspositionIsOneEdit) {
  constexpr std::array<std::string_view, 3> kKeys = {"material", "type", "file"};
  EXPECT_EQ(nearest_name("tpye", kKeys), "type");
  EXPECT_EQ(nearest_name("ytpe", kKeys), "type");
  EXPECT_EQ(nearest_name("fiel", kKeys), "file");
  EXPECT_EQ(nearest_name("matreial", kKeys), "material");
  EXPECT_EQ(nearest_name("mtaeiral", kKeys), "material");  // two swaps: 2 <= 8/3
  // Only neighbours: "epyt" is no swap away from "type".
  EXPECT_EQ(nearest_name("epyt", kKeys), "");
}

TEST(NearestName, ExactMatchIsItsOwnNearest) {
  EXPECT_EQ(nearest_name("radius", kMaterialKeys), "radius");
}

TEST(NearestName, ShortKeysAllowOnlyOneEdit) {
  // "fov" -> "fov_y" needs 2 edits, more than max(1, 3/3) = 1.
  EXPECT_EQ(nearest_name("fov", kMaterialKeys), "");
  EXPECT_EQ(nearest_name("fovy", kMaterialKeys), "fov_y");
}

TEST(NearestName, NoSuggestionForUnrelatedWords) {
  EXPECT_EQ(nearest_name("banana", kMaterialKeys), "");
  EXPECT_EQ(nearest_name("ALBEDO", kMaterialKeys), "");
  EXPECT_EQ(nearest_name("xyz", kMaterialKeys), "");
  EXPECT_EQ(nearest_name("albedo", std::span<const std::string_view>()), "");
}

TEST(NearestName, TiesGoToTheFirstCandidate) {
  constexpr std::array<std::string_view, 2> ab = {"ac", "ad"};
  constexpr std::array<std::string_view, 2> ba = {"ad", "ac"};
  EXPECT_EQ(nearest_name("ab", ab), "ac");
  EXPECT_EQ(nearest_name("ab", ba), "ad");
}

}  // namespace
}  // namespace pathlab
