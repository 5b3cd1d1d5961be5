#include "variants/cache_store.h"

#include <curl/curl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/content_hash.h"

namespace sg {
namespace {

namespace fs = std::filesystem;

constexpr const char* kEntryFormat = "shadergen-entry 1";

std::string localPath(const std::string& dir, const std::string& key) {
  return (fs::path(dir) / key.substr(0, 2) / key).string();
}

// What a reader gets of a file: all of it, or nullopt when it is not there.
std::optional<std::string> readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A unique temporary per process and write, renamed into place: a reader (another build
// sharing the directory) sees the old entry, the new one or none, never part of one; a
// build killed mid-write leaves only "<key>.tmp.*", which no reader takes for an entry.
void writeLocal(const std::string& path, const std::string& bytes) {
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  std::string tmp = fmt::format("{}.tmp.{}.{}", path, static_cast<int>(getpid()), counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return;  // a read-only cache only costs speed
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      return;
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) fs::remove(tmp, ec);
}

size_t appendBody(char* data, size_t size, size_t n, void* out) {
  std::string& s = *static_cast<std::string*>(out);
  if (s.size() + size * n > (size_t{256} << 20)) return 0;  // no entry is that large: abort
  s.append(data, size * n);
  return size * n;
}

}  // namespace

std::string redactUrl(const std::string& url) {
  size_t scheme = url.find("://");
  size_t from = scheme == std::string::npos ? 0 : scheme + 3;
  size_t end = url.find_first_of("/?#", from);
  size_t at = url.rfind('@', end == std::string::npos ? url.size() : end);
  if (at == std::string::npos || at < from) return url;
  return url.substr(0, from) + "***" + url.substr(at);
}

std::string chooseCacheUrl(const std::string& flag, const std::string& manifest) {
  if (!flag.empty()) {
    if (redactUrl(flag) != flag)
      throw std::invalid_argument(fmt::format(
          "'{}' holds credentials; they come only from the environment (SHADERGEN_CACHE_AUTH=user:password, or "
          "the URL in SHADERGEN_CACHE_URL), never from a command line others can read",
          redactUrl(flag)));
    return flag;
  }
  if (const char* env = std::getenv("SHADERGEN_CACHE_URL"); env && *env) return env;
  return manifest;  // loadManifest refuses credentials there
}

std::string sealEntry(const std::string& key, const std::string& body) {
  return fmt::format("{} {}\n", kEntryFormat, Sha256().field(key).field(body).hex()) + body;
}

std::optional<std::string> openEntry(const std::string& key, const std::string& bytes, std::string& why) {
  size_t eol = bytes.find('\n');
  const std::string head = std::string(kEntryFormat) + " ";
  if (eol == std::string::npos || bytes.compare(0, head.size(), head) != 0 || eol != head.size() + 64) {
    why = bytes.empty() ? "empty" : "no entry header (damaged, or written by another version)";
    return std::nullopt;
  }
  std::string body = bytes.substr(eol + 1);
  if (Sha256().field(key).field(body).hex() != bytes.substr(head.size(), 64)) {
    why = "its SHA-256 does not match its contents (corrupt or truncated)";
    return std::nullopt;
  }
  return body;
}

// ---- the server: GET and PUT with libcurl -----------------------------------------------

struct CacheStore::Remote {
  std::string base;  // without a trailing '/'
  std::mutex lock;
  std::vector<CURL*> idle;  // easy handles keep their connection for the next request
  std::atomic<bool> down{false};

  ~Remote() {
    for (CURL* c : idle) curl_easy_cleanup(c);
  }
  CURL* take(const CacheStoreOptions& o) {
    {
      std::lock_guard<std::mutex> g(lock);
      if (!idle.empty()) {
        CURL* c = idle.back();
        idle.pop_back();
        return c;
      }
    }
    CURL* c = curl_easy_init();
    if (!c) return nullptr;
    curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(c, CURLOPT_CONNECTTIMEOUT_MS, o.connectTimeoutMs);
    curl_easy_setopt(c, CURLOPT_TIMEOUT_MS, o.timeoutMs);
    curl_easy_setopt(c, CURLOPT_FOLLOWLOCATION, 0L);
    if (!o.auth.empty()) {
      curl_easy_setopt(c, CURLOPT_USERPWD, o.auth.c_str());
      curl_easy_setopt(c, CURLOPT_HTTPAUTH, CURLAUTH_BASIC);
    }
    return c;
  }
  void give(CURL* c) {
    std::lock_guard<std::mutex> g(lock);
    idle.push_back(c);
  }
};

CacheStore::CacheStore(CacheStoreOptions opts) : opts_(std::move(opts)), redacted_(redactUrl(opts_.url)) {
  if (opts_.url.empty()) return;
  static std::once_flag init;
  std::call_once(init, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
  remote_ = std::make_unique<Remote>();
  remote_->base = opts_.url;
  while (!remote_->base.empty() && remote_->base.back() == '/') remote_->base.pop_back();
}

CacheStore::~CacheStore() = default;

void CacheStore::warnOnce(const std::string& message) {
  if (remote_->down.exchange(true)) return;
  std::lock_guard<std::mutex> g(lock_);
  stats_.remoteFailed = true;
  if (opts_.warn) opts_.warn(message);
}

void CacheStore::reject(const std::string& where, const std::string& key, const std::string& why) {
  std::lock_guard<std::mutex> g(lock_);
  ++stats_.rejected;
  if (opts_.warn) opts_.warn(fmt::format("{} cache entry {} rejected: {}; rebuilding it", where, key, why));
}

std::optional<std::string> CacheStore::get(const std::string& key) {
  std::string why;
  if (!opts_.dir.empty()) {
    if (auto bytes = readWhole(localPath(opts_.dir, key))) {
      if (auto body = openEntry(key, *bytes, why)) {
        std::lock_guard<std::mutex> g(lock_);
        ++stats_.localHits;
        return body;
      }
      reject("local", key, why);
    }
  }
  if (!remote_ || remote_->down) return std::nullopt;
  CURL* c = remote_->take(opts_);
  if (!c) return std::nullopt;
  std::string bytes;
  const std::string url = fmt::format("{}/{}/{}", remote_->base, key.substr(0, 2), key);
  curl_easy_setopt(c, CURLOPT_URL, url.c_str());
  curl_easy_setopt(c, CURLOPT_HTTPGET, 1L);
  curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, appendBody);
  curl_easy_setopt(c, CURLOPT_WRITEDATA, &bytes);
  CURLcode rc = curl_easy_perform(c);
  long status = 0;
  curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &status);
  remote_->give(c);
  if (rc != CURLE_OK) {
    warnOnce(fmt::format("remote cache {} unreachable ({}); building without it", redacted_, curl_easy_strerror(rc)));
    return std::nullopt;
  }
  if (status == 404) return std::nullopt;
  if (status != 200) {
    warnOnce(fmt::format("remote cache {} answered HTTP {} to GET; building without it", redacted_, status));
    return std::nullopt;
  }
  auto body = openEntry(key, bytes, why);
  if (!body) {
    reject("remote", key, why);
    return std::nullopt;
  }
  if (!opts_.dir.empty()) writeLocal(localPath(opts_.dir, key), bytes);
  std::lock_guard<std::mutex> g(lock_);
  ++stats_.remoteHits;
  return body;
}

void CacheStore::put(const std::string& key, const std::string& body) {
  const std::string bytes = sealEntry(key, body);
  if (!opts_.dir.empty()) writeLocal(localPath(opts_.dir, key), bytes);
  if (!remote_ || remote_->down) return;
  CURL* c = remote_->take(opts_);
  if (!c) return;
  const std::string url = fmt::format("{}/{}/{}", remote_->base, key.substr(0, 2), key);
  curl_slist* headers = curl_slist_append(nullptr, "Content-Type: application/octet-stream");
  headers = curl_slist_append(headers, "Expect:");
  std::string ignored;
  curl_easy_setopt(c, CURLOPT_URL, url.c_str());
  curl_easy_setopt(c, CURLOPT_CUSTOMREQUEST, "PUT");
  curl_easy_setopt(c, CURLOPT_POSTFIELDS, bytes.data());
  curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, static_cast<curl_off_t>(bytes.size()));
  curl_easy_setopt(c, CURLOPT_HTTPHEADER, headers);
  curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, appendBody);
  curl_easy_setopt(c, CURLOPT_WRITEDATA, &ignored);
  CURLcode rc = curl_easy_perform(c);
  long status = 0;
  curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &status);
  // The handle goes back as a plain GET handle.
  curl_easy_setopt(c, CURLOPT_CUSTOMREQUEST, nullptr);
  curl_easy_setopt(c, CURLOPT_HTTPHEADER, nullptr);
  curl_easy_setopt(c, CURLOPT_POSTFIELDS, nullptr);
  curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, static_cast<curl_off_t>(-1));
  remote_->give(c);
  curl_slist_free_all(headers);
  if (rc != CURLE_OK) {
    warnOnce(fmt::format("remote cache {} unreachable ({}); building without it", redacted_, curl_easy_strerror(rc)));
    return;
  }
  if (status < 200 || status >= 300) {
    warnOnce(fmt::format("remote cache {} answered HTTP {} to PUT; building without it", redacted_, status));
    return;
  }
  std::lock_guard<std::mutex> g(lock_);
  ++stats_.remoteStores;
}

CacheStoreStats CacheStore::stats() const {
  std::lock_guard<std::mutex> g(lock_);
  return stats_;
}

}  // namespace sg
