// What a run writes outside the images: the lock on its output folder and the results JSON.
#pragma once
#include <filesystem>

#include <nlohmann/json.hpp>

namespace iblcheck {

// Holds <out>/.iblcheck.lock for the run: a second run into the same folder is refused (UsageError
// naming the pid that holds it) instead of interleaving its files with this one's. An empty
// folder: no lock.
class OutDirLock {
  public:
    explicit OutDirLock(const std::filesystem::path& dir);
    ~OutDirLock();
    OutDirLock(const OutDirLock&) = delete;
    OutDirLock& operator=(const OutDirLock&) = delete;

  private:
    int fd_ = -1;
};

// Written beside `file` and renamed over it, so a reader never sees half a document.
void write_json_atomically(const std::filesystem::path& file, const nlohmann::json& j);

} // namespace iblcheck
