// Loading a glTF model (gltf_load.h). The only translation unit with tinygltf's implementation.
#define TINYGLTF_IMPLEMENTATION
#include "rig/gltf_load.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string_view>

#include <nlohmann/json.hpp>

#include "common/diagnostics.h"
#include "rig/gltf_accessor.h"
#include "rig/gltf_import.h"
#include "rig/gltf_meshopt.h"

namespace sg::gltf {
namespace {

// Textures are not needed (and the test models ship without them): accept every image as is.
// tinygltf keeps an external image's URI but not a data URI's: one is made again from the
// decoded bytes, so that `bake` writes the image back instead of `"bufferView": -1`.
bool skipImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
               int size, void*) {
  if (image && image->uri.empty() && image->bufferView < 0 && bytes && size > 0)
    image->uri = "data:" + (image->mimeType.empty() ? std::string("application/octet-stream") : image->mimeType) +
                 ";base64," + tinygltf::base64_encode(bytes, static_cast<unsigned int>(size));
  return true;
}

// --- loading: the file, its JSON and its buffer files, checked before tinygltf sees them ---

// The first bracket nested deeper than kMaxGltfJsonDepth (1-based line and column), if any.
// tinygltf copies extras and extensions recursively, so depth is checked before parsing.
std::optional<std::pair<int, int>> tooDeep(const char* p, size_t n) {
  int depth = 0, line = 1, col = 1;
  bool inString = false, escaped = false;
  for (size_t i = 0; i < n; ++i) {
    char c = p[i];
    if (inString) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxGltfJsonDepth) return std::make_pair(line, col);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
    if (c == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::nullopt;
}

// Reads a model or buffer file: regular files only (a FIFO or /dev/zero would block or never
// end), at most kMaxGltfFileBytes.
bool readBounded(const std::string& path, std::string& out, std::string& why) {
  std::error_code ec;
  auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) return why = "no such file", false;
  if (!std::filesystem::is_regular_file(st)) return why = "not a regular file", false;
  if (std::filesystem::file_size(path, ec) > kMaxGltfFileBytes)
    return why = fmt::format("larger than the limit of {}", mib(kMaxGltfFileBytes)), false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return why = std::strerror(errno), false;
  out.clear();
  char chunk[65536];
  while (in) {
    in.read(chunk, sizeof chunk);
    out.append(chunk, static_cast<size_t>(in.gcount()));
    if (out.size() > kMaxGltfFileBytes)
      return why = fmt::format("larger than the limit of {}", mib(kMaxGltfFileBytes)), false;
  }
  if (in.bad()) return why = "read error", false;
  return true;
}

// Buffer files (uri: "x.bin") must resolve, symlinks followed, inside the model's folder: a
// model from elsewhere must not read /etc/passwd or ../../secrets into a shader's inputs.
struct BufferFiles {
  std::filesystem::path root;  // canonical model folder; empty: no buffer files at all
  std::string refused;         // the first refusal, reported instead of "File not found"
  size_t bytesRead = 0;        // all buffer files together stay under kMaxGltfFileBytes too
  std::vector<std::string> read;  // the buffer files read, in order (depfiles, cache keys)
};

bool insideRoot(BufferFiles& ctx, const std::string& path) {
  std::error_code ec;
  auto c = std::filesystem::weakly_canonical(path, ec);
  bool inside = !ec && !ctx.root.empty() &&
                std::mismatch(ctx.root.begin(), ctx.root.end(), c.begin(), c.end()).first == ctx.root.end();
  if (!inside && ctx.refused.empty())
    ctx.refused = ctx.root.empty()
                      ? fmt::format("buffer file '{}' refused: this model has no folder to read files from", path)
                      : fmt::format("buffer file '{}' lies outside the model's folder '{}'", path, ctx.root.string());
  return inside;
}

bool bufferFileExists(const std::string& path, void* user) {
  auto& ctx = *static_cast<BufferFiles*>(user);
  std::error_code ec;
  return (ctx.root.empty() || std::filesystem::exists(path, ec)) && insideRoot(ctx, path);
}
std::string keepPath(const std::string& path, void*) { return path; }
bool readBufferFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto& ctx = *static_cast<BufferFiles*>(user);
  if (!insideRoot(ctx, path)) return false;
  std::string bytes, why;
  if (!readBounded(path, bytes, why)) {
    if (err) *err += why;
    return false;
  }
  ctx.bytesRead += bytes.size();
  ctx.read.push_back(path);
  if (ctx.bytesRead > kMaxGltfFileBytes) {
    if (err) *err += fmt::format("the buffer files together are larger than the limit of {}", mib(kMaxGltfFileBytes));
    return false;
  }
  out->assign(bytes.begin(), bytes.end());
  return true;
}
bool writeNothing(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

uint32_t le32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;  // glTF is little-endian, as is every host this builds for
}

// GLB layout checked with 64-bit arithmetic (tinygltf 2.7 lets a BIN chunk header run 8
// bytes past the end). Returns the JSON chunk.
std::pair<size_t, size_t> checkGlb(const std::string& b, const std::string& file) {
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0)
    fail(file, "not a binary glTF file (no 'glTF' header); a .glb must start with the GLB header");
  uint64_t length = le32(b, 8), json = le32(b, 12);
  if (le32(b, 4) != 2) fail(file, fmt::format("GLB version {} is not supported (only 2)", le32(b, 4)));
  if (length > b.size())
    fail(file, fmt::format("the GLB header claims {} bytes but the file has {}", length, b.size()));
  if (le32(b, 16) != 0x4E4F534A || json == 0 || 20 + json > length)
    fail(file, fmt::format("the GLB's first chunk must be JSON of at most {} bytes", length - 20));
  uint64_t bin = 20 + json;
  if (bin < length) {
    if (bin + 8 > length || bin + 8 + le32(b, static_cast<size_t>(bin)) > length)
      fail(file, fmt::format("the GLB's BIN chunk at byte {} runs past the end of the file ({} bytes)", bin, length));
  }
  return {20, static_cast<size_t>(json)};
}

// tinygltf's message, with nlohmann's "parse error at line L, column C" made a location.
[[noreturn]] void failLoad(const std::string& file, std::string err, bool glb, const BufferFiles& files) {
  if (!files.refused.empty()) fail(file, files.refused);
  while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
  std::replace(err.begin(), err.end(), '\n', ' ');
  if (err.empty()) err = "unknown error";
  int line = 0, col = 0;
  auto at = err.find("parse error at line ");
  if (at != std::string::npos && std::sscanf(err.c_str() + at, "parse error at line %d, column %d", &line, &col) == 2) {
    auto colon = err.find(": ", at);
    std::string what = colon == std::string::npos ? err : err.substr(colon + 2);
    if (!glb) throw InputError(SourceLoc{file, line, col}, "invalid JSON: " + what);
    fail(file, fmt::format("invalid JSON in the GLB's JSON chunk at line {}, column {}: {}", line, col, what));
  }
  fail(file, "cannot load the glTF model: " + err);
}

// Extensions whose required use does not change the vertex data, skinning or animation
// shadergen reads (materials and textures are not read at all).
bool readableExtension(const std::string& name) {
  return name == "KHR_mesh_quantization" || name == "EXT_meshopt_compression" || name == "EXT_mesh_gpu_instancing" ||
         name.rfind("KHR_materials_", 0) == 0 || name.rfind("KHR_texture_", 0) == 0 ||
         name.rfind("EXT_texture_", 0) == 0;
}

// 1-based line and column of the first `needle` at or after `from` in the JSON text.
std::pair<int, int> lineColumn(const char* p, size_t n, const std::string& needle, size_t from = 0) {
  std::string_view all(p, n);
  size_t at = all.find(needle, from);
  if (at == std::string_view::npos) return {0, 0};
  int line = 1, col = 1;
  for (size_t i = 0; i < at; ++i) {
    if (p[i] == '\n') ++line, col = 1;
    else ++col;
  }
  return {line, col};
}

// The JSON as tinygltf should see it: refuses a required extension it cannot read (naming
// it, with its line and column in a .gltf), and gives EXT_meshopt_compression's fallback
// buffers (no uri, no data: gltfpack -c) a one-byte data URI, recording their declared length
// for decodeMeshopt. Returns "" when the JSON is to be loaded unchanged (also when it does
// not parse: tinygltf reports that with its location).
std::string prepareJson(const char* p, size_t n, bool glb, const std::string& file, std::map<int, size_t>& fallbacks) {
  nlohmann::json j = nlohmann::json::parse(p, p + n, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return "";
  if (auto req = j.find("extensionsRequired"); req != j.end() && req->is_array())
    for (const auto& e : *req) {
      if (!e.is_string() || readableExtension(e.get<std::string>())) continue;
      const std::string name = e.get<std::string>();
      std::string msg = fmt::format("the model requires the extension {} (extensionsRequired), which shadergen cannot "
                                    "read; it reads KHR_mesh_quantization, EXT_meshopt_compression and EXT_mesh_gpu_instancing",
                                    name);
      std::string_view all(p, n);
      auto [line, col] = lineColumn(p, n, "\"" + name + "\"", all.find("\"extensionsRequired\""));
      if (!glb && line > 0) throw InputError(SourceLoc{file, line, col}, msg);
      fail(file, line > 0 ? fmt::format("{} (JSON chunk line {}, column {})", msg, line, col) : msg);
    }
  auto buffers = j.find("buffers");
  if (buffers == j.end() || !buffers->is_array()) return "";
  bool changed = false;
  for (size_t i = 0; i < buffers->size(); ++i) {
    auto& b = (*buffers)[i];
    if (!b.is_object() || b.contains("uri")) continue;
    auto ext = b.find("extensions");
    if (ext == b.end() || !ext->is_object()) continue;
    auto mo = ext->find("EXT_meshopt_compression");
    if (mo == ext->end() || !mo->is_object()) continue;
    auto fallback = mo->find("fallback");
    if (fallback == mo->end() || *fallback != true) continue;
    auto len = b.find("byteLength");
    if (len == b.end() || !len->is_number_unsigned())
      fail(file, fmt::format("buffer {}: a fallback buffer needs a non-negative integer byteLength", i));
    fallbacks[static_cast<int>(i)] = len->get<size_t>();
    b["byteLength"] = 1;  // tinygltf refuses an empty data URI: one zero byte, replaced by decodeMeshopt
    b["uri"] = "data:application/octet-stream;base64,AA==";
    changed = true;
  }
  return changed ? j.dump() : "";
}

// A GLB with its JSON chunk replaced (padded with spaces to 4 bytes, as GLB requires).
std::string replaceGlbJson(const std::string& glb, size_t jsonAt, size_t jsonSize, std::string json) {
  while (json.size() % 4) json += ' ';
  std::string out = glb.substr(0, 12);
  auto put32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  put32(static_cast<uint32_t>(json.size()));
  put32(0x4E4F534A);
  out += json;
  out.append(glb, jsonAt + jsonSize, le32(glb, 8) - (jsonAt + jsonSize));  // the BIN chunk, if any
  uint32_t total = static_cast<uint32_t>(out.size());
  std::memcpy(&out[8], &total, 4);
  return out;
}

}  // namespace

size_t loadChecked(const std::string& file, const std::string* text, const std::string& baseDir,
                   tinygltf::Model& model, std::vector<std::string>* buffersRead) {
  std::string bytes, why;
  if (!text && !readBounded(file, bytes, why)) fail(file, "cannot read the glTF model: " + why);
  const std::string& b = text ? *text : bytes;
  if (b.size() > kMaxGltfFileBytes) fail(file, fmt::format("the glTF model is larger than {}", mib(kMaxGltfFileBytes)));
  // A binary model is known by its magic, as viewers know it, whatever its file is called.
  bool glb = !text && (lower(std::filesystem::path(file).extension().string()) == ".glb" || b.rfind("glTF", 0) == 0);
  auto [jsonAt, jsonSize] = glb ? checkGlb(b, file) : std::make_pair(size_t{0}, b.size());
  if (auto deep = tooDeep(b.data() + jsonAt, jsonSize)) {
    std::string msg = fmt::format("JSON nested deeper than {} levels", kMaxGltfJsonDepth);
    if (!glb) throw InputError(SourceLoc{file, deep->first, deep->second}, msg);
    fail(file, fmt::format("{} in the GLB's JSON chunk (line {}, column {})", msg, deep->first, deep->second));
  }

  BufferFiles files;
  std::string dir = text ? baseDir : std::filesystem::path(file).parent_path().string();
  if (!text && dir.empty()) dir = ".";
  std::error_code ec;
  if (!dir.empty()) files.root = std::filesystem::canonical(dir, ec);
  if (ec) files.root.clear();
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skipImage, nullptr);
  loader.SetFsCallbacks(tinygltf::FsCallbacks{bufferFileExists, keepPath, readBufferFile, writeNothing, &files});
  std::map<int, size_t> fallbacks;
  std::string patchedJson = prepareJson(b.data() + jsonAt, jsonSize, glb, file, fallbacks);
  std::string patched = patchedJson.empty() ? "" : glb ? replaceGlbJson(b, jsonAt, jsonSize, patchedJson) : patchedJson;
  const std::string& given = patched.empty() ? b : patched;
  if (given.size() > UINT32_MAX) fail(file, "the glTF model is too large");
  std::string err, warn;
  const auto* data = reinterpret_cast<const unsigned char*>(given.data());
  std::string base = files.root.string();
  bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, static_cast<unsigned int>(given.size()), base)
                : loader.LoadASCIIFromString(&model, &err, &warn, given.data(), static_cast<unsigned int>(given.size()),
                                             base);
  if (!ok) failLoad(file, err, glb, files);
  if (buffersRead) *buffersRead = files.read;
  // The budget follows the compressed input: decompressed bytes are decoded data.
  size_t input = b.size();
  for (const auto& buf : model.buffers) input += buf.data.size();
  decodeMeshopt(model, fallbacks, decodedBudget(input, kMaxGltfDecodedBytes), file);
  return input;
}

}  // namespace sg::gltf
