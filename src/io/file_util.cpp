#include "io/file_util.h"

#include <unistd.h>

#include <cctype>
#include <fstream>
#include <random>
#include <string>

#include "pic/io.h"
#include "pic/types.h"

namespace pic::detail {

std::string lower_extension(const std::filesystem::path& path) {
  std::string e = path.extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

std::filesystem::path temp_path_for(const std::filesystem::path& path) {
  // Unique per process (pid) and per call (random): two writers of one path never share a
  // temporary file.
  auto tmp = path;
  std::string name = ".";
  name += path.stem().string();
  name += ".tmp";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(std::random_device{}());
  name += path.extension().string();
  tmp.replace_filename(name);
  return tmp;
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  const auto tmp = temp_path_for(path);
  try {
    write(tmp);
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw IoError("cannot write " + path.string() + ": " + ec.message());
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

std::vector<uint8_t> read_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw IoError("cannot read " + path.string() + ": no such file");
  if (std::filesystem::is_directory(path, ec)) throw IoError("cannot read " + path.string() + ": is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read " + path.string() + ": permission denied or unreadable");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read " + path.string());
  return bytes;
}

void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError("cannot write " + path.string() + ": cannot create file");
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw IoError("cannot write " + path.string() + ": write failed (disk full?)");
  });
}

}  // namespace pic::detail

namespace pic {
void write_text(const std::filesystem::path& path, const std::string& text) {
  detail::write_bytes(path, std::vector<uint8_t>(text.begin(), text.end()));
}
}  // namespace pic
