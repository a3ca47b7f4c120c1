// The entries of the on-disk stores (precomputes, instruction counts, metrics; issue 33): each named
// by a hash of every input, written whole or not at all, and read back only when it starts as its
// store writes it. The stores are an optimisation: a failure to write is no error, and an entry that
// cannot be read is a miss (the work is done again).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace iblcheck {

// A store's folder: $`env_var` when set ("0": off, an empty path), else `default_dir`.
std::filesystem::path store_dir(const char* env_var, const std::filesystem::path& default_dir);

// The entry's bytes after `head` (the layout's magic, and the key again where the store writes it, so
// a renamed or misplaced file is a miss); none when the file is missing or does not start with `head`.
std::optional<std::string> read_store_entry(const std::filesystem::path& file, std::string_view head);

// Writes `bytes` into a temporary file of this process and thread, renamed onto `file` (readers see a
// whole entry or none), creating the folder; a failure to write is ignored.
void write_store_entry(const std::filesystem::path& file, std::string_view bytes);

// Whether this process has written a store entry: only then can the stores have grown, so only then
// does a command prune them (store_budget.h).
bool store_entries_written();

} // namespace iblcheck
