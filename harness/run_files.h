// What a run writes outside the images: its output folder and the results JSON.
#pragma once
#include <filesystem>

#include <nlohmann/json.hpp>

namespace iblcheck {

// The output folder of a run (--out). The run is written into a fresh folder beside it,
// <parent>/.<name>.partial, and swapped in whole when complete (rename with RENAME_EXCHANGE), so
// --out never holds one run's index.html or results.json beside another run's images, even after
// a run killed with -9 (whose partial folder the next run clears). An existing --out holding files
// is replaced only with `force`, and only when it is a run folder (results.json, index.html or
// .iblcheck.lock in it); a second run while one is writing is refused (UsageError naming the pid
// that holds <partial>/.iblcheck.lock). An empty path: no folder, dir() is empty.
class RunFolder {
  public:
    RunFolder(const std::filesystem::path& out, bool force);
    ~RunFolder(); // not committed (an error): the partial folder is removed
    RunFolder(const RunFolder&) = delete;
    RunFolder& operator=(const RunFolder&) = delete;

    // Where the run writes: the partial folder.
    const std::filesystem::path& dir() const { return partial_; }
    // Swaps the complete run in as --out (the earlier run, if any, is removed). Throws InputError
    // naming --out when it cannot. (Folders, exchanged: not kernel/atomic_file.h, which writes a file.)
    void commit();

  private:
    std::filesystem::path out_, partial_;
    int lock_fd_ = -1, old_lock_fd_ = -1;
    bool committed_ = false;
};

// Written beside `file` and renamed over it, so a reader never sees half a document. Throws
// InputError naming `file` when it cannot be written in full (a full disk).
void write_json_atomically(const std::filesystem::path& file, const nlohmann::json& j);

} // namespace iblcheck
