// Projected Newton iterations (untangle_newton.h).
#include "geometry/untangle_newton.h"

namespace hexpeel::untangle_detail {

NewtonRun newton(Problem& prob, NewtonSystem& sys, const WinslowKernel& kernel, Eigen::VectorXd& x,
                 const UntangleParams& p, int max_iterations) {
  NewtonRun run;
  const int64_t n = x.size();
  Eigen::VectorXd g(n), gt(n), xt(n);
  double f = prob.evaluate(x, g, kernel);
  for (int it = 0; it < max_iterations; ++it) {
    const auto t0 = Clock::now();
    sys.assemble(prob, kernel);  // prob.pos holds x: evaluate() was last called at x
    double mean_diag = 0.0;
    for (int32_t i : sys.diag_index) mean_diag += sys.h.valuePtr()[i];
    mean_diag = std::max(mean_diag / std::max<int64_t>(1, n), 1e-300);
    double shift = 1e-10 * mean_diag;
    bool ok = false;
    for (int attempt = 0; attempt < 8 && !ok; ++attempt, shift *= 100.0) {
      ok = sys.factorize(shift);
      ++run.factorizations;
    }
    if (!ok) {
      run.solve_time_s += seconds_since(t0);
      break;
    }
    const Eigen::VectorXd dx = sys.solve(-g);
    run.solve_time_s += seconds_since(t0);
    const double slope = g.dot(dx);
    if (!(slope < 0.0)) break;
    double alpha = 1.0, ft = 0.0;
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls, alpha *= 0.5) {
      xt = x + alpha * dx;
      ft = prob.evaluate(xt, gt, kernel);
      if (std::isfinite(ft) && ft <= f + 1e-4 * alpha * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      prob.evaluate(x, g, kernel);  // leave prob.pos at x
      break;
    }
    ++run.iterations;
    const double gain = f - ft;
    x.swap(xt);
    g.swap(gt);
    f = ft;
    if (gain <= p.newton_rtol * std::abs(f)) break;
  }
  return run;
}

}  // namespace hexpeel::untangle_detail
