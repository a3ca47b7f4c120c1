// Files named by the user (images, environments, suites, goldens and their sidecars, lists of
// pairs, results and history files) are read only when they are regular files. A FIFO or a
// character device blocks the first read forever when nothing writes to it, and a folder opens
// on Linux but reads as nothing: both would hang the tool or give a message that names no file.
#pragma once
#include <fstream>
#include <string>

namespace iblcheck {

// Throws InputError "<path>: file not found", or "<path>: is a folder|a FIFO (named pipe)|a
// character device|a block device|a socket, not a regular file". Symbolic links are followed.
void require_regular_file(const std::string& path);

// require_regular_file, then opens it (binary); InputError "<path>: cannot open (<why>)" when the
// open fails (permissions).
std::ifstream open_input_file(const std::string& path);

} // namespace iblcheck
