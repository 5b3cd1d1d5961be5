// Where `shadergen build` keeps its content-addressed entries: a local directory, and
// optionally a shared HTTP cache over it (docs/variants.md, "The remote cache"). An entry
// is named by its key (a SHA-256) and starts with the SHA-256 of its key and body, checked
// on every read, local or remote: a corrupt or truncated entry is reported and is a miss
// (the variant is rebuilt and the entry written again). Reads try the directory, then the
// server (a verified remote hit is stored locally); writes go to both. The server is an
// ordinary one (nginx with WebDAV PUT, any server taking GET and PUT of files): GET
// URL/ab/abcd... answers an entry or 404, PUT stores one. A server that cannot be reached
// costs one warning and the connect timeout, once: the rest of the build goes without it.
#pragma once
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace sg {

struct CacheStoreOptions {
  std::string dir;   // "" = no local directory
  std::string url;   // "" = no remote; http(s)://host[:port]/path (credentials only from the environment)
  std::string auth;  // "user:password" for the server (SHADERGEN_CACHE_AUTH), or ""
  long connectTimeoutMs = 1500;
  long timeoutMs = 20000;  // one request, all of it
  // Warnings (a corrupt entry, the server unreachable); called under a lock. Never given
  // credentials: URLs in messages are redacted.
  std::function<void(const std::string&)> warn;
};

struct CacheStoreStats {
  size_t localHits = 0, remoteHits = 0, remoteStores = 0, rejected = 0;
  bool remoteFailed = false;
};

class CacheStore {
 public:
  explicit CacheStore(CacheStoreOptions opts);
  ~CacheStore();
  CacheStore(const CacheStore&) = delete;
  CacheStore& operator=(const CacheStore&) = delete;

  // The body stored under `key`, verified; nullopt on a miss or a rejected entry. Thread-safe.
  std::optional<std::string> get(const std::string& key);
  // Stores the body under `key` locally (temporary file + rename) and remotely (PUT).
  void put(const std::string& key, const std::string& body);
  CacheStoreStats stats() const;
  bool enabled() const { return !opts_.dir.empty() || !opts_.url.empty(); }
  const std::string& redactedUrl() const { return redacted_; }

 private:
  struct Remote;
  void warnOnce(const std::string& message);
  void reject(const std::string& where, const std::string& key, const std::string& why);
  CacheStoreOptions opts_;
  std::string redacted_;
  std::unique_ptr<Remote> remote_;
  mutable std::mutex lock_;
  CacheStoreStats stats_;
};

// The entry's bytes for a body (header line: format and the SHA-256 of key and body), and
// back: the body, or nullopt with `why` set when the bytes are not that entry's.
std::string sealEntry(const std::string& key, const std::string& body);
std::optional<std::string> openEntry(const std::string& key, const std::string& bytes, std::string& why);

// "scheme://user:secret@host/p" -> "scheme://***@host/p": what messages show of a URL.
std::string redactUrl(const std::string& url);

// The remote cache's URL for a build: --cache-url, else $SHADERGEN_CACHE_URL, else the
// manifest's `cache_url`. Credentials come only from the environment: a --cache-url holding
// them throws std::invalid_argument (the manifest's are refused when it loads).
std::string chooseCacheUrl(const std::string& flag, const std::string& manifest);

}  // namespace sg
