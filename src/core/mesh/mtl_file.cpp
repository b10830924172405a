// Reading .obj material libraries for their normal-map file names (see mtl_file.hpp).
#include "mesh/mtl_file.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {
namespace {

namespace fs = std::filesystem;

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string trim(const std::string& text) {
  size_t begin = 0, end = text.size();
  while (begin < end && isSpace(text[begin])) ++begin;
  while (end > begin && isSpace(text[end - 1])) --end;
  return text.substr(begin, end - begin);
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// The lines of a text file, without their line ends ("\n" or "\r\n"), comments and surrounding
// blanks; blank lines dropped.
std::vector<std::string> contentLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    // A comment starts a line or follows a blank: "tex#2.png" is a file name.
    for (size_t i = 0; i < line.size(); ++i) {
      if (line[i] == '#' && (i == 0 || isSpace(line[i - 1]))) {
        line.erase(i);
        break;
      }
    }
    line = trim(line);
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// Splits "keyword rest of line" at the first blank.
std::pair<std::string, std::string> keywordAndRest(const std::string& line) {
  size_t end = 0;
  while (end < line.size() && !isSpace(line[end])) ++end;
  return {lower(line.substr(0, end)), trim(line.substr(end))};
}

std::string unquote(const std::string& name) {
  if (name.size() >= 2 && name.front() == '"' && name.back() == '"') {
    return name.substr(1, name.size() - 2);
  }
  return name;
}

bool isNumber(const std::string& token) {
  if (token.empty()) return false;
  char* end = nullptr;
  std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size();
}

// How many arguments a texture option takes: -o/-s/-t take one to three numbers (the others
// default), so they take "up to 3 numbers"; -1 for an option this reader does not know.
int optionArguments(const std::string& option, bool* numbers_up_to_three) {
  *numbers_up_to_three = false;
  static const char* const kOneArgument[] = {"-bm",   "-blendu",    "-blendv",  "-boost",
                                             "-cc",   "-clamp",     "-imfchan", "-texres",
                                             "-type", "-colorspace"};
  for (const char* known : kOneArgument) {
    if (option == known) return 1;
  }
  if (option == "-mm") return 2;
  if (option == "-o" || option == "-s" || option == "-t") {
    *numbers_up_to_three = true;
    return 3;
  }
  return -1;
}

// The file name of a map statement's arguments: leading options skipped, the rest of the line
// taken whole (file names may contain spaces), a quoted name unquoted.
std::string mapFileName(const std::string& arguments) {
  std::string rest = trim(arguments);
  while (!rest.empty() && rest[0] == '-') {
    size_t end = 0;
    while (end < rest.size() && !isSpace(rest[end])) ++end;
    const std::string option = lower(rest.substr(0, end));
    bool up_to_three = false;
    const int count = optionArguments(option, &up_to_three);
    if (count < 0) break;  // not an option we know: a file name starting with '-'
    rest = trim(rest.substr(end));
    for (int i = 0; i < count && !rest.empty(); ++i) {
      size_t token_end = 0;
      while (token_end < rest.size() && !isSpace(rest[token_end])) ++token_end;
      if (up_to_three && !isNumber(rest.substr(0, token_end))) break;
      rest = trim(rest.substr(token_end));
    }
  }
  return unquote(rest);
}

std::string readText(const fs::path& path, bool* ok) {
  std::ifstream file(path, std::ios::binary);
  *ok = file.good();
  if (!*ok) return {};
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  *ok = !file.bad();
  return text;
}

}  // namespace

std::vector<MtlMaterial> parseMtl(const std::string& text) {
  std::vector<MtlMaterial> materials;
  for (const std::string& line : contentLines(text)) {
    const auto [keyword, rest] = keywordAndRest(line);
    if (keyword == "newmtl") {
      materials.push_back(MtlMaterial{rest, {}, {}});
      continue;
    }
    if (materials.empty()) continue;  // a map before any material belongs to none
    MtlMaterial& material = materials.back();
    if ((keyword == "norm" || keyword == "map_kn") && material.norm.empty()) {
      material.norm = mapFileName(rest);
    } else if ((keyword == "map_bump" || keyword == "bump") && material.bump.empty()) {
      material.bump = mapFileName(rest);
    }
  }
  return materials;
}

std::vector<std::string> parseObjMaterialLibraries(const std::string& text,
                                                   const std::string& obj_directory) {
  std::vector<std::string> libraries;
  for (const std::string& line : contentLines(text)) {
    const auto [keyword, rest] = keywordAndRest(line);
    if (keyword != "mtllib" || rest.empty()) continue;
    if (rest.find('"') != std::string::npos) {
      // Quoted names, each one name whatever it contains; unquoted words between them too.
      std::string name;
      bool quoted = false;
      for (const char c : rest + " ") {
        if (c == '"') {
          quoted = !quoted;
        } else if (!quoted && isSpace(c)) {
          if (!name.empty()) libraries.push_back(name);
          name.clear();
        } else {
          name += c;
        }
      }
      continue;
    }
    std::error_code ec;
    if (fs::is_regular_file(fs::path(obj_directory) / rest, ec)) {
      libraries.push_back(rest);
      continue;
    }
    std::istringstream words(rest);
    for (std::string word; words >> word;) libraries.push_back(word);
  }
  return libraries;
}

std::vector<ObjMaterial> readObjMaterials(const std::string& obj_path) {
  // Only the mtllib lines matter: stream the .obj (it may be hundreds of MB) and keep those.
  std::ifstream obj(obj_path, std::ios::binary);
  if (!obj) throw Error("mesh '" + obj_path + "' cannot be read");
  std::string library_lines, line;
  while (std::getline(obj, line)) {
    if (keywordAndRest(trim(line)).first == "mtllib") library_lines += line + "\n";
  }
  if (obj.bad()) throw Error("mesh '" + obj_path + "' cannot be read");

  std::error_code ec;
  const fs::path obj_directory = fs::absolute(obj_path, ec).lexically_normal().parent_path();
  std::vector<ObjMaterial> materials;
  for (const std::string& library :
       parseObjMaterialLibraries(library_lines, obj_directory.string())) {
    fs::path mtl_path = obj_directory / library;  // an absolute library stays absolute
    if (!fs::exists(mtl_path, ec) && library.find('\\') != std::string::npos) {
      std::string slashed = library;  // written on Windows: "materials\\a.mtl"
      std::replace(slashed.begin(), slashed.end(), '\\', '/');
      mtl_path = obj_directory / slashed;
    }
    bool ok = false;
    const std::string text = readText(mtl_path, &ok);
    if (!ok) continue;
    const std::string directory = mtl_path.lexically_normal().parent_path().string();
    for (MtlMaterial& material : parseMtl(text)) {
      materials.push_back(ObjMaterial{std::move(material), directory});
    }
  }
  return materials;
}

const ObjMaterial* findObjMaterial(const std::vector<ObjMaterial>& materials,
                                   const std::string& name) {
  for (const ObjMaterial& material : materials) {
    if (material.material.name == name) return &material;
  }
  return nullptr;
}

}  // namespace detail
}  // namespace norm2tex
