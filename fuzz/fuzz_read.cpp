// libFuzzer harness for one file reader (HEXPEEL_FUZZ_EXT names its extension): the input bytes
// are written to a file of that extension and read as a surface, then as a hex mesh; whatever the
// bytes, the readers must return a Status (ASan/UBSan catch the rest). A surface that reads is
// validated, so the checks run on whatever a reader lets through.
#include "hexpeel/io.h"
#include "hexpeel/validation.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

#ifndef HEXPEEL_FUZZ_EXT
#error "HEXPEEL_FUZZ_EXT must name the extension, e.g. \".obj\""
#endif

namespace {

std::filesystem::path scratch_file() {
  const char* dir = std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp";
  return std::filesystem::path(dir) /
         ("hexpeel_fuzz_" + std::to_string(::getpid()) + HEXPEEL_FUZZ_EXT);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path = scratch_file();
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 0) std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    return 0;
  }
  hexpeel::PolygonSoup soup;
  int64_t hexes_ignored = 0;
  if (hexpeel::read_surface(path, soup, &hexes_ignored).ok() && soup.points.size() < 100000)
    (void)hexpeel::run_validation(soup);
  hexpeel::HexMesh mesh;
  int64_t others = 0;
  (void)hexpeel::read_hex_mesh(path, mesh, &others);
  return 0;
}
