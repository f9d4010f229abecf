// HexMesh helpers.
#include "hexpeel/hex_mesh.h"

namespace hexpeel {

Hex mirrored(const Hex& h) { return {h[0], h[3], h[2], h[1], h[4], h[7], h[6], h[5]}; }

}  // namespace hexpeel
