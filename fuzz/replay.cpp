// Replays files through the fuzz harness bodies without libFuzzer (any compiler), plus a few
// seeded mutations of each file (bit flips, truncations, duplicated and deleted spans), so
// the normal g++ build and CI keep a fuzz smoke run over the committed corpus.
//   fuzz_replay [--mutations N] KIND=DIR_OR_FILE ...     KIND: obj stl ply off gltf pic, or
//   auto (the file's own extension picks the reader, as for tests/data/fuzz/)
// Exit 0 when every input is either accepted or refused with InvalidInput/IoError; any other
// outcome is a crash (or an escaped exception reported here, exit 1).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "harness.h"

namespace {

std::vector<uint8_t> read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<uint8_t> mutate(std::vector<uint8_t> b, std::mt19937_64& rng) {
  const int edits = 1 + int(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    const size_t n = b.size();
    const size_t at = n ? rng() % n : 0;
    switch (rng() % 6) {
      case 0:  // flip a bit
        if (n) b[at] ^= uint8_t(1u << (rng() % 8));
        break;
      case 1:  // set a byte to an interesting value
        if (n) b[at] = std::vector<uint8_t>{0, 0xff, 0x7f, 0x80, '-', '9', ' ', '\n'}[rng() % 8];
        break;
      case 2:  // truncate
        b.resize(at);
        break;
      case 3: {  // delete a span
        const size_t len = std::min(n - at, size_t(rng() % 16));
        b.erase(b.begin() + long(at), b.begin() + long(at + len));
        break;
      }
      case 4: {  // duplicate a span
        const size_t len = std::min(n - at, size_t(rng() % 32));
        std::vector<uint8_t> span(b.begin() + long(at), b.begin() + long(at + len));
        b.insert(b.begin() + long(at), span.begin(), span.end());
        break;
      }
      default:  // a digit run that makes counts huge
        b.insert(b.begin() + long(at), 9, '9');
        break;
    }
  }
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  int mutations = 0;
  size_t runs = 0;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--mutations" && a + 1 < argc) {
      mutations = std::atoi(argv[++a]);
      continue;
    }
    const size_t eq = arg.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "usage: fuzz_replay [--mutations N] KIND=PATH ...\n");
      return 2;
    }
    const std::string kind = arg.substr(0, eq);
    const std::filesystem::path path = arg.substr(eq + 1);
    std::vector<std::filesystem::path> files;
    if (std::filesystem::is_directory(path)) {
      for (const auto& e : std::filesystem::directory_iterator(path))
        if (e.is_regular_file() && e.path().extension() != ".md") files.push_back(e.path());
    } else {
      files.push_back(path);
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      const std::vector<uint8_t> bytes = read_all(f);
      std::mt19937_64 rng(std::hash<std::string>{}(f.filename().string()));
      for (int m = -1; m < mutations; ++m) {
        const std::vector<uint8_t> input = m < 0 ? bytes : mutate(bytes, rng);
        try {
          if (kind != "auto") {
            pic::fuzz::run_harness(kind, input.data(), input.size());
          } else if (f.extension() == ".pic") {
            pic::fuzz::run_pic(input.data(), input.size());
          } else {
            pic::fuzz::run_reader(input.data(), input.size(), f.extension().string());
          }
        } catch (const std::exception& e) {
          const std::string out = "fuzz-finding-" + kind + "-" + f.filename().string() + "-" + std::to_string(m);
          std::ofstream(out, std::ios::binary).write(reinterpret_cast<const char*>(input.data()), long(input.size()));
          std::fprintf(stderr, "FINDING: %s (mutation %d, saved as %s) escaped with: %s\n", f.c_str(), m,
                       out.c_str(), e.what());
          return 1;
        }
        ++runs;
      }
    }
  }
  std::printf("fuzz_replay: %zu inputs, no finding\n", runs);
  return 0;
}
