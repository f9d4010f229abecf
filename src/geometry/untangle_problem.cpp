// Building the optimization problem, hex quality and region minimization (untangle_problem.h).
#include "geometry/untangle_problem.h"

#include "hexpeel/quality.h"

namespace hexpeel::untangle_detail {

void build_problem(Problem& prob, const std::vector<Hex>& hexes, const std::vector<uint8_t>& fixed,
                   double collinear_tol, int32_t* forced, int32_t* forced_nonpositive,
                   double* forced_min) {
  const int32_t np = static_cast<int32_t>(prob.base.size());
  prob.free_index.assign(np, -1);
  prob.free_point.clear();
  for (int32_t v = 0; v < np; ++v)
    if (!fixed[v]) {
      prob.free_index[v] = static_cast<int32_t>(prob.free_point.size());
      prob.free_point.push_back(v);
    }
  prob.corners.clear();
  prob.hexes.clear();
  prob.hex_mask.clear();
  prob.group_start.assign(1, 0);
  prob.num_centres = 0;
  for (const Hex& h : hexes) {
    uint16_t mask = 0;
    for (int c = 0; c < 8; ++c) {
      const std::array<int32_t, 4> k{h[c], h[kHexCornerFrames[c][0]], h[kHexCornerFrames[c][1]],
                                     h[kHexCornerFrames[c][2]]};
      int nfix = 0;
      std::array<int32_t, 4> fx{};
      for (int32_t v : k)
        if (fixed[v]) fx[nfix++] = v;
      bool is_forced = nfix == 4;
      if (nfix == 3) {
        const Vec3 a = prob.base[fx[1]] - prob.base[fx[0]], b = prob.base[fx[2]] - prob.base[fx[0]];
        is_forced = a.cross(b).norm() <= collinear_tol * a.norm() * b.norm();
      }
      if (is_forced) {
        if (forced) ++*forced;
        const Vec3 e0 = prob.base[k[1]] - prob.base[k[0]], e1 = prob.base[k[2]] - prob.base[k[0]],
                   e2 = prob.base[k[3]] - prob.base[k[0]];
        if (forced_nonpositive && e0.dot(e1.cross(e2)) <= 0.0) ++*forced_nonpositive;
        if (forced_min) {
          const double l = e0.norm() * e1.norm() * e2.norm();
          *forced_min = std::min(*forced_min, l > 0.0 ? e0.dot(e1.cross(e2)) / l : -1.0);
        }
      } else {
        prob.corners.push_back(k);
        mask |= static_cast<uint16_t>(1u << c);
      }
    }
    // The centre Jacobian depends on all 8 points: it can change unless all are fixed.
    bool any_free = false;
    for (int32_t v : h) any_free |= !fixed[v];
    if (any_free) {
      mask |= static_cast<uint16_t>(1u << untangle_detail::kCentre);
      ++prob.num_centres;
    }
    if (mask != 0) {
      prob.group_start.push_back(static_cast<int32_t>(prob.corners.size()));
      prob.hexes.push_back(h);
      prob.hex_mask.push_back(mask);
    }
  }
  prob.finish_setup();
}

HexQuality hex_quality(const HexMesh& mesh) {
  HexQuality q;
  std::vector<double> sj(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.hexes.size(), 512),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t h = r.begin(); h != r.end(); ++h) {
                        std::array<Vec3, 8> c;
                        for (int k = 0; k < 8; ++k) c[k] = mesh.points[mesh.hexes[h][k]];
                        sj[h] = scaled_jacobian(c);
                      }
                    });
  for (double s : sj) {
    q.min = std::min(q.min, s);
    if (s <= 0.0) ++q.nonpositive;
  }
  return q;
}

int32_t minimize_region(Problem& prob, Problem& sub, const std::vector<uint8_t>& sub_fixed,
                        const QualityKernel& kernel, Eigen::VectorXd& x,
                        const UntangleParams& params, int iterations, double delta,
                        UntanglePhaseStats& st) {
  sub.base = prob.pos;
  build_problem(sub, prob.hexes, sub_fixed, params.collinear_tol, nullptr, nullptr);
  const int32_t ns = static_cast<int32_t>(sub.free_point.size());
  Eigen::VectorXd xs(3 * ns);
  for (int32_t u = 0; u < ns; ++u) xs.segment<3>(3 * u) = sub.base[sub.free_point[u]];
  const int ev_sub = sub.evaluations;
  const int64_t cev_sub = sub.corner_evaluations;
  st.iterations += minimize(sub, kernel, xs, params, iterations, StopRule::delta, delta);
  st.evaluations += sub.evaluations - ev_sub;
  st.corner_evaluations += sub.corner_evaluations - cev_sub;
  for (int32_t u = 0; u < ns; ++u)
    x.segment<3>(3 * prob.free_index[sub.free_point[u]]) = xs.segment<3>(3 * u);
  return ns;
}

}  // namespace hexpeel::untangle_detail
