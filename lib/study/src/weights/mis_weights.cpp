#include "envmis/study/weights/mis_weights.h"

#include <cmath>

#include <Eigen/Dense>

namespace envmis {

OptimalAlpha solve_optimal_alpha(const double* a, const double* b, int m) noexcept {
    // Bounded sizes: Eigen keeps these on the stack, so the solve allocates nothing.
    using Matrix =
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, kMaxTechniques, kMaxTechniques>;
    using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor, kMaxTechniques, 3>;
    OptimalAlpha result;
    if (m < 1 || m > kMaxTechniques) return result;
    const Matrix A = Eigen::Map<const Matrix>(a, m, m);
    const Rhs B = Eigen::Map<const Rhs>(b, m, 3);
    if (!A.allFinite() || !B.allFinite()) return result;
    // The exact condition number from the eigenvalues (cheap at m <= 3): LDLT's own
    // estimate stays finite on singular matrices, whose zero pivots it skips.
    const Eigen::SelfAdjointEigenSolver<Matrix> eigen(A, Eigen::EigenvaluesOnly);
    const auto& lambda = eigen.eigenvalues();
    result.rcond =
        eigen.info() == Eigen::Success && lambda.maxCoeff() > 0 ? lambda.minCoeff() / lambda.maxCoeff() : 0.0;
    if (!(result.rcond >= 1e-9)) return result;
    const Rhs alpha = A.ldlt().solve(B);
    if (!alpha.allFinite()) return result;
    for (int k = 0; k < m; ++k)
        for (int c = 0; c < 3; ++c) result.alpha[k][c] = static_cast<float>(alpha(k, c));
    result.solved = true;
    return result;
}

}  // namespace envmis
