// libFuzzer harness for `hexpeel quality`: the bytes are read as a legacy VTK hex mesh and, when
// they read, measured (scaled Jacobian, topology, boundary); any hex mesh that reads must be
// measured without a crash, whatever its ids, coordinates or connectivity.
#include "hexpeel/io.h"
#include "hexpeel/quality.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path =
      std::filesystem::path(std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp") /
      ("hexpeel_fuzz_quality_" + std::to_string(::getpid()) + ".vtk");
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 0) std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    return 0;
  }
  hexpeel::HexMesh mesh;
  int64_t others = 0;
  if (hexpeel::read_hex_mesh(path, mesh, &others).ok() && mesh.num_hexes() < 20000)
    (void)hexpeel::run_quality(mesh);
  return 0;
}
