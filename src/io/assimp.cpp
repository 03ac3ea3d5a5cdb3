// glTF/GLB (and any other format assimp knows) through assimp, guarded:
// - assimp's internal asserts (ai_assert, compiled into Debian's build) call
//   Assimp::aiAssertViolation through the PLT; PIC defines that symbol, so the executable's
//   definition wins and turns an assert into an exception instead of abort(). The installed
//   headers have no setAiAssertHandler, which later assimp versions offer for the same purpose.
// - for .gltf/.glb only assimp's glTF importers stay registered: otherwise a broken glTF is
//   handed to every other importer whose signature test it passes (fuzzing found a 164-byte
//   "GLB" that the DXF importer then took, using 1.9 GB);
// - a GLB header's declared lengths are checked against the file size before assimp sees it
//   (assimp 5.2 allocates what the header declares);
// - the import runs in a forked child with a time and memory budget (see "Isolation" below);
// - the scene is validated (aiProcess_ValidateDataStructure) and every face index is checked
//   again while collecting;
// - the work of flattening the node tree (instances) is budgeted against the file size, and the
//   node tree's depth is bounded, so a small file cannot expand into gigabytes or recurse forever.
#include <assimp/BaseImporter.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <poll.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "io/readers.h"

namespace Assimp {
// Replaces assimp's own handler (which prints and aborts). Declared in <assimp/ai_assert.h>
// only for ASSIMP_BUILD_DEBUG builds, hence the local declaration.
void aiAssertViolation(const char* expression, const char* file, int line);
void aiAssertViolation(const char* expression, const char* file, int line) {
  throw pic::InvalidInput(std::string("malformed file (assimp internal check failed: ") + expression + " at " +
                          file + ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

// AddressSanitizer reserves terabytes of address space: no RLIMIT_AS under it.
#if defined(__SANITIZE_ADDRESS__)
#define PIC_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PIC_UNDER_ASAN 1
#endif
#endif

namespace pic::detail {
namespace {

constexpr int kMaxNodeDepth = 256;  // deeper scene graphs are refused (and cycles end here)

struct Collector {
  const aiScene* scene;
  RawGeometry& out;
  uint64_t budget;  // vertices + faces still allowed to be visited

  void node(const aiNode* node, const aiMatrix4x4& parent, int depth) {
    if (depth > kMaxNodeDepth) throw InvalidInput("the scene graph is deeper than " + std::to_string(kMaxNodeDepth));
    const aiMatrix4x4 m = parent * node->mTransformation;
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      if (node->mMeshes[k] >= scene->mNumMeshes) throw InvalidInput("a node refers to a missing mesh");
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[k]];
      const uint64_t cost = uint64_t(mesh->mNumVertices) + mesh->mNumFaces;
      if (cost > budget)
        throw InvalidInput("the scene expands to more geometry than its size allows (instancing budget)");
      budget -= cost;
      const auto base = uint32_t(out.positions.size());
      if (out.positions.size() + mesh->mNumVertices > UINT32_MAX) throw InvalidInput("more than 2^32 vertices");
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D p = m * mesh->mVertices[v];
        out.positions.push_back({p.x, p.y, p.z});
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines carry no surface
        std::array<uint32_t, 3> t{};
        for (int c = 0; c < 3; ++c) {
          if (face.mIndices[c] >= mesh->mNumVertices) throw InvalidInput("a face index is out of range");
          t[c] = base + face.mIndices[c];
        }
        out.triangles.push_back(t);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) this->node(node->mChildren[c], m, depth + 1);
  }
};

uint32_t u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);  // GLB is little-endian, as is every machine PIC builds on
  return v;
}

// GLB: "glTF", version, total length, then (version 2) chunks of length + type + data, or
// (version 1) content length + format. Every length must fit in the file.
void check_glb_header(Bytes b) {
  if (b.size < 4 || std::memcmp(b.data, "glTF", 4) != 0) return;  // not binary glTF: assimp decides
  if (b.size < 20) throw InvalidInput("GLB: the header is cut short");
  const uint32_t version = u32(b.data + 4), length = u32(b.data + 8);
  if (version != 1 && version != 2) throw InvalidInput("GLB: unknown version " + std::to_string(version));
  if (length > b.size)
    throw InvalidInput("GLB: the header declares " + std::to_string(length) + " bytes but the file has only " +
                       std::to_string(b.size) + " bytes");
  if (version == 1) {
    if (u32(b.data + 12) > b.size - 20) throw InvalidInput("GLB: the content length exceeds the file");
    return;
  }
  for (size_t at = 12; at + 8 <= length;) {
    const uint64_t chunk = u32(b.data + at);
    if (chunk > length - at - 8) throw InvalidInput("GLB: a chunk length exceeds the file");
    at += 8 + size_t(chunk);
  }
}

bool is_gltf_importer(const aiImporterDesc* d) {
  const std::string exts = d && d->mFileExtensions ? d->mFileExtensions : "";
  return exts.find("gltf") != std::string::npos || exts.find("glb") != std::string::npos;
}

}  // namespace

// The import itself, in this process.
RawGeometry import_here(Bytes bytes, const std::string& ext) {
  Assimp::Importer importer;
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (gltf) {
    check_glb_header(bytes);
    for (size_t i = importer.GetImporterCount(); i-- > 0;) {
      if (is_gltf_importer(importer.GetImporterInfo(i))) continue;
      Assimp::BaseImporter* other = importer.GetImporter(i);
      importer.UnregisterLoader(other);  // which does not delete it
      delete other;
    }
  }
  const aiScene* scene = importer.ReadFileFromMemory(
      bytes.data, bytes.size, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_SortByPType,
      ext.empty() ? "" : ext.c_str() + 1);
  if (!scene || !scene->mRootNode) {
    const std::string why = importer.GetErrorString();
    if (!gltf && (why.find("No suitable reader") != std::string::npos || why.find("unsupported") != std::string::npos))
      throw IoError("unknown or unsupported mesh format '" + ext + "'");
    throw InvalidInput("malformed mesh (" + why + ")");
  }
  RawGeometry g;
  // Instancing may repeat a mesh; allow a generous multiple of what the file itself holds.
  Collector c{scene, g, 64 * uint64_t(bytes.size) + (uint64_t(1) << 20)};
  c.node(scene->mRootNode, aiMatrix4x4(), 0);
  return g;
}

namespace {

// ---------------------------------------------------------------------------------------
// Isolation. assimp 5.2 still dereferences null on some malformed glTF that passes every
// check above (fuzzing: a primitive whose "indices" names a float accessor), and no pre-check
// short of a full glTF validator catches them all. So the import runs in a forked child with a
// time budget (and, outside sanitizer builds, an address-space budget); the child sends the
// raw geometry or the error back through a pipe. A child that dies or overruns becomes
// InvalidInput in the caller, which never shares assimp's fate.

enum class Outcome : uint8_t { Ok = 0, Invalid = 1, Io = 2 };

bool write_all(int fd, const void* p, size_t n) {
  const auto* b = static_cast<const uint8_t*>(p);
  while (n > 0) {
    const ssize_t w = ::write(fd, b, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    b += w;
    n -= size_t(w);
  }
  return true;
}

[[noreturn]] void child(Bytes bytes, const std::string& ext, int fd) {
  // The child speaks through the pipe only: assimp's own messages, or the report of a crash
  // inside it (the C library's or a sanitizer's), would otherwise reach the user's terminal
  // beside pic's one-line error.
  if (const int devnull = ::open("/dev/null", O_WRONLY); devnull >= 0) {
    ::dup2(devnull, 2);
    ::close(devnull);
  }
#if !defined(PIC_UNDER_ASAN)
  // Address space: what the process already maps plus 4 GiB plus 64 bytes per input byte.
  long pages = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  const rlim_t limit = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + (rlim_t(4) << 30) + 64 * rlim_t(bytes.size);
  const rlimit rl{limit, limit};
  ::setrlimit(RLIMIT_AS, &rl);
#endif
  Outcome outcome = Outcome::Ok;
  std::string message;
  RawGeometry g;
  try {
    g = import_here(bytes, ext);
  } catch (const InvalidInput& e) {
    outcome = Outcome::Invalid;
    message = e.what();
  } catch (const IoError& e) {
    outcome = Outcome::Io;
    message = e.what();
  } catch (const std::bad_alloc&) {
    outcome = Outcome::Invalid;
    message = "the importer (assimp) ran out of its memory budget";
  } catch (const std::exception& e) {
    outcome = Outcome::Invalid;
    message = std::string("malformed file (assimp: ") + e.what() + ")";
  }
  const uint64_t head[3] = {message.size(), g.positions.size(), g.triangles.size()};
  const bool ok = write_all(fd, &outcome, 1) && write_all(fd, head, sizeof head) &&
                  write_all(fd, message.data(), message.size()) &&
                  write_all(fd, g.positions.data(), g.positions.size() * sizeof(Vec3)) &&
                  write_all(fd, g.triangles.data(), g.triangles.size() * sizeof(g.triangles[0]));
  ::_exit(ok ? 0 : 1);  // no atexit handlers or destructors of the parent's state
}

// Reads everything the child sends until it closes the pipe or the deadline passes.
bool read_until_eof(int fd, std::vector<uint8_t>& out, std::chrono::steady_clock::time_point deadline) {
  uint8_t buf[1 << 16];
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, int(std::min<long long>(left.count(), 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) return false;
    if (r == 0) continue;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n == 0;
    out.insert(out.end(), buf, buf + n);
  }
}

}  // namespace

RawGeometry read_with_assimp(Bytes bytes, const std::string& ext) {
  int fds[2];
  if (::pipe(fds) != 0) throw IoError(std::string("cannot start the importer: ") + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw IoError(std::string("cannot start the importer: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(bytes, ext, fds[1]);
  }
  ::close(fds[1]);
  // Time budget: 10 s plus 1 s per MB, generous for a real file, short for a hang.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10 + bytes.size / 1000000);
  std::vector<uint8_t> reply;
  const bool complete = read_until_eof(fds[0], reply, deadline);
  ::close(fds[0]);
  if (!complete) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!complete) throw InvalidInput("the importer (assimp) did not finish within its time budget");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || reply.size() < 1 + 24) {
    if (WIFSIGNALED(status))
      throw InvalidInput("malformed file: the importer (assimp) crashed on it (signal " +
                         std::to_string(WTERMSIG(status)) + ")");
    throw InvalidInput("malformed file: the importer (assimp) failed on it");
  }
  uint64_t head[3];
  std::memcpy(head, reply.data() + 1, sizeof head);
  const size_t need = 25 + head[0] + head[1] * sizeof(Vec3) + head[2] * sizeof(std::array<uint32_t, 3>);
  if (head[0] > reply.size() || head[1] > reply.size() || head[2] > reply.size() || reply.size() != need)
    throw InvalidInput("malformed file: the importer (assimp) failed on it");
  const auto outcome = Outcome(reply[0]);
  const std::string message(reinterpret_cast<const char*>(reply.data()) + 25, size_t(head[0]));
  if (outcome == Outcome::Io) throw IoError(message);
  if (outcome != Outcome::Ok) throw InvalidInput(message);
  RawGeometry g;
  g.positions.resize(size_t(head[1]));
  g.triangles.resize(size_t(head[2]));
  const uint8_t* p = reply.data() + 25 + head[0];
  if (!g.positions.empty()) std::memcpy(g.positions.data(), p, g.positions.size() * sizeof(Vec3));
  if (!g.triangles.empty())  // memcpy from or to null is undefined even for 0 bytes
    std::memcpy(g.triangles.data(), p + g.positions.size() * sizeof(Vec3), g.triangles.size() * sizeof(g.triangles[0]));
  for (const auto& t : g.triangles)
    for (uint32_t i : t)
      if (i >= g.positions.size()) throw InvalidInput("malformed file: the importer (assimp) failed on it");
  return g;
}

}  // namespace pic::detail
