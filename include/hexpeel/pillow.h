// Forced configurations and pillowing (Mitchell & Tautges, "Pillowing doublets", 1995).
//
// With the boundary fixed, a hex corner whose 4 points are all boundary vertices has its Jacobian
// decided by the surface: a flat doublet (two boundary faces of one hex at about 180 degrees) or
// three boundary faces at a concave corner cannot be made positive by any placement. Pillowing a
// shrink set S of hexes inserts one new hex on every face of S's boundary (S's hexes move onto
// copies of their boundary vertices), which frees those corners and keeps the surface as it is.
// Topology only (positions are read to detect forced corners); placement comes after.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/quad_surface.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/status.h"

#include <cstdint>
#include <string_view>
#include <vector>

namespace hexpeel {

enum class PillowMode {
  none,       ///< never pillow
  automatic,  ///< pillow a shrink set around the forced configurations only, when there are any
  all,        ///< pillow the whole boundary
};
std::string_view to_string(PillowMode m);

enum class ForcedKind {
  flat_doublet,    ///< two boundary faces of the hex meet at the corner's edges (about 180 deg)
  concave_corner,  ///< three boundary faces of the hex meet at the corner
  fixed_corner,    ///< all 4 points on the boundary, fewer than two boundary faces of the hex
  collinear,       ///< the corner's 3 fixed points are collinear: its Jacobian is always 0
};
std::string_view to_string(ForcedKind k);

/// A hex corner no placement of interior vertices can make positive enough.
struct ForcedConfiguration {
  int32_t hex = -1;
  int32_t corner = -1;      ///< local corner 0..7
  ForcedKind kind = ForcedKind::fixed_corner;
  double scaled_jacobian = 0.0;  ///< of the corner tetrahedron (fixed by the surface)
};

struct PillowParams {
  PillowMode mode = PillowMode::automatic;
  /// A forced corner whose scaled Jacobian (det of unit edge vectors) is <= this counts as a
  /// forced configuration (dimensionless, in [-1, 1)). Below 0 the hex is inverted whatever the
  /// placement; 0.2 (two boundary faces within ~12 deg of flat) also pillows corners that would
  /// cap the mesh's minimum at a useless value.
  double forced_sj = 0.2;
  /// Rings of face neighbours added to the forced hexes to make the local shrink set (0..10):
  /// a larger set spreads the pillow's distortion over more hexes.
  int grow = 2;
  /// In auto mode, pillow the whole boundary instead when the local shrink set holds at least
  /// this fraction of the hexes that touch the boundary (in [0, 1]; 1 = always local): dense
  /// forced corners are better served by the whole layer, sparse ones locally.
  double whole_fraction = 0.25;
  /// Inward margin (unit normals, 0..1) a boundary vertex's copy should have over the quads the
  /// pillow puts at it: the pillow hexes' corners at the copy cannot be better than about this
  /// margin, so at a vertex below it hexes that are not forced are kept out of S while that
  /// raises the smaller of the copy's margin and the one left for the hexes kept out (0 = only
  /// what a copy needs to exist, a margin of 1e-3). Off by default: it can raise the minimum but
  /// can also leave hexes inverted.
  double target_margin = 0.0;
  /// Pillow passes at most (values below 1 count as 1). A pass after the first pillows, locally, forced hexes the
  /// previous one had to keep out of S (at a saddle vertex), giving that vertex another copy; it
  /// is kept only when it lowers the count of forced corners and unserved vertices.
  int max_passes = 3;
  /// Hexes of the complex pillowed as the forced ones are: in mode auto the local shrink set
  /// grows from them and from the forced hexes alike, and they make a pillow wanted even with no
  /// forced configuration. Ids out of range are ignored.
  std::vector<int32_t> seed_hexes;
  /// Pillow around seed_hexes alone, in any mode (the repair pillow of the pipeline,
  /// MeshParams::repair_rounds, whose boundary has its layer already): the forced configurations
  /// are not pillowed, the whole boundary never is, and there is one pass. Each seed's set
  /// (grown by `grow` rings) joins S, in the order given, only while S still pillows to a ball;
  /// seeds that end inside the fitted S are not tried again.
  bool seeds_only = false;
};

struct PillowStats {
  int32_t forced = 0;               ///< forced configurations found before pillowing
  int32_t flat_doublets = 0, concave_corners = 0, fixed_corners = 0, collinear = 0;
  int32_t seed_hexes = 0;           ///< PillowParams::seed_hexes in range (distinct)
  int32_t forced_after = 0;         ///< forced configurations left after pillowing
  int32_t excluded_vertices = 0;    ///< boundary vertices with no strictly inward direction
  int32_t dropped_hexes = 0;        ///< hexes kept out of S so every copy has an inward direction
  int32_t unserved_vertices = 0;    ///< boundary vertices whose copy still has none (0 unless
                                    ///< only the unfitted whole set gave a ball)
  int32_t shrink_set = 0;           ///< hexes in the pillowed shrink sets, summed over passes
  int32_t new_hexes = 0, new_vertices = 0;
  bool whole_boundary = false;      ///< local pillowing could not be used; the whole set was
  int32_t passes = 0;               ///< pillow passes applied (0 = no pillow)
  double time_s = 0.0;
};

struct PillowResult {
  Status status;
  HexComplex complex;                        ///< the input complex, pillowed or not
  std::vector<ForcedConfiguration> forced;   ///< found before pillowing, by hex then corner
  PillowStats stats;
};

/// Forced corners of `complex` (boundary vertices at `surface`'s positions): corners whose 4
/// points are boundary vertices with scaled Jacobian <= forced_sj, and corners whose 3 boundary
/// points are collinear. Sorted by hex, then corner.
std::vector<ForcedConfiguration> find_forced_configurations(const QuadSurface& surface,
                                                            const HexComplex& complex,
                                                            double forced_sj = 0.2);

/// Whether some unit direction d has d . n < -margin for every unit normal n (an empty list has
/// one, vacuously). Exact for any number of normals. The pillow keeps out of S enough hexes at a
/// boundary vertex that the quads it pillows there have one: the copy must sit inside each.
bool has_inward_direction(const std::vector<Vec3>& unit_normals, double margin);

/// Detects forced configurations and pillows as `params.mode` says. The result's boundary is the
/// input surface, vertex for vertex (copies are new interior vertices, input_vertex = -1), and the
/// complex stays a ball (checked; a pillow that breaks it is not applied).
PillowResult run_pillow(const QuadSurface& surface, const HexComplex& complex,
                        const PillowParams& params = {}, const Context& ctx = {});

}  // namespace hexpeel
