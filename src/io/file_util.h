// Small file helpers shared by the .pic and mesh writers.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace pic::detail {

/// A temporary path next to `path`, keeping its extension (so format detection still works).
std::filesystem::path temp_path_for(const std::filesystem::path& path);

/// Runs `write(tmp)` then renames tmp over `path`; removes tmp on failure. An existing file
/// at `path` is never truncated by a failed write. \throws IoError.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write);

/// The path's extension in lower case, with its dot ("" when none).
std::string lower_extension(const std::filesystem::path& path);

std::vector<uint8_t> read_file(const std::filesystem::path& path);
void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes);

}  // namespace pic::detail
