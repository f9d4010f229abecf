// Internal to src/pipeline: what run_mesh (pipeline.cpp) and the surface repair (repair.cpp)
// share.
#pragma once

#include "hexpeel/pipeline.h"

#include <chrono>

namespace hexpeel::pipeline_detail {

double seconds_since(std::chrono::steady_clock::time_point t0);

/// Pillows `complex` as `pillow` says, places, untangles and optimizes it and checks the result:
/// r's pillow, forced, placement, untangle, mesh, quality and status, and their timings.
void embed(const QuadSurface& surface, const HexComplex& complex, const MeshParams& params,
           const PillowParams& pillow, const Context& ctx, MeshResult& r,
           HexComplex* used = nullptr);

/// The seconds of every stage in t.
double total_seconds(const MeshTimings& t);

/// MeshParams::repair_surface: the repair's ways in order (elimination of the refined surface,
/// of the one split into six everywhere when that mesh is not valid, the fill through
/// tetrahedra), as repair_fill selects them; the first result is kept unless a later one is
/// better (better_result).
MeshResult mesh_repaired(const SurfaceDiagnosis& diagnosis, const MeshParams& params,
                         const Context& ctx, double check_s);

}  // namespace hexpeel::pipeline_detail
