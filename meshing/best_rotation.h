#pragma once
// The best rotation for a 3×3 correlation matrix (the local step of Laplacian and
// as-rigid-as-possible editing). Header-only so that it inlines into the per-frame loop of
// laplacian_edit.cpp; included only there and by its test, since it pulls in Eigen/Dense.

#include <cmath>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <Eigen/Dense>
#pragma GCC diagnostic pop

namespace lobe {

/// The rotation R maximising tr(Rᵀa), i.e. minimising Σⱼ ‖e′ⱼ − R eⱼ‖² for a = Σⱼ e′ⱼ eⱼᵀ,
/// by the SVD (a = UΣVᵀ, R = UVᵀ with the reflection removed). The slow, sure path.
inline Eigen::Matrix3d best_rotation_svd(const Eigen::Matrix3d& a)
{
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    const Eigen::Matrix3d& v = svd.matrixV();
    if ((u * v.transpose()).determinant() < 0.0)
        u.col(2) = -u.col(2); // singular values are sorted: flip the least certain axis
    return u * v.transpose();
}

/// The same rotation by Horn's quaternion method (J. Opt. Soc. Am. A 4(4), 1987): R(q) for
/// the eigenvector q of the largest eigenvalue of the symmetric, traceless 4×4 matrix N(a),
/// since tr(R(q)ᵀa) = qᵀN q. The eigenvalue comes from Newton's method on N's characteristic
/// polynomial λ⁴ − 2‖a‖²λ² − 8 det(a) λ + det N, started above every root (at √3‖a‖ ≥
/// σ₁ + σ₂ + σ₃), where it falls monotonically to the largest root; the eigenvector is a
/// column of adj(N − λI) = μ q qᵀ (Theobald's QCP, Acta Cryst. A61, 2005). No trigonometry
/// and no iteration over the matrix (one rotation is fitted per energy row and rotation
/// iteration on every pinch frame; timings in docs/pinch-editing.md). The result is the best
/// proper rotation also when det a < 0.
/// Returns false where q cannot be shown to be accurate to 1e-9 (the largest eigenvalue too
/// close to the next one: a of rank one or less; or a not finite); the SVD decides then.
inline bool best_rotation_horn(const Eigen::Matrix3d& a, Eigen::Matrix3d& rotation)
{
    // N for S = aᵀ (S_xy = Σ eₓ e′ᵧ), in Horn's notation.
    const double sxx = a(0, 0), syy = a(1, 1), szz = a(2, 2);
    const double sxy = a(1, 0), syx = a(0, 1), sxz = a(2, 0), szx = a(0, 2), syz = a(2, 1), szy = a(1, 2);
    const double n[4][4] = {{sxx + syy + szz, syz - szy, szx - sxz, sxy - syx},
                            {syz - szy, sxx - syy - szz, sxy + syx, szx + sxz},
                            {szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy},
                            {sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz}};
    const double squared_norm = a.squaredNorm();
    const double c2 = -2.0 * squared_norm, c1 = -8.0 * a.determinant();
    // det N by the 2×2 minors of rows 0, 1 and rows 2, 3 (Laplace expansion).
    const double s0 = n[0][0] * n[1][1] - n[0][1] * n[1][0], s1 = n[0][0] * n[1][2] - n[0][2] * n[1][0];
    const double s2 = n[0][0] * n[1][3] - n[0][3] * n[1][0], s3 = n[0][1] * n[1][2] - n[0][2] * n[1][1];
    const double s4 = n[0][1] * n[1][3] - n[0][3] * n[1][1], s5 = n[0][2] * n[1][3] - n[0][3] * n[1][2];
    const double t0 = n[2][2] * n[3][3] - n[2][3] * n[3][2], t1 = n[2][1] * n[3][3] - n[2][3] * n[3][1];
    const double t2 = n[2][1] * n[3][2] - n[2][2] * n[3][1], t3 = n[2][0] * n[3][3] - n[2][3] * n[3][0];
    const double t4 = n[2][0] * n[3][2] - n[2][2] * n[3][0], t5 = n[2][0] * n[3][1] - n[2][1] * n[3][0];
    const double c0 = s0 * t0 - s1 * t1 + s2 * t2 + s3 * t3 - s4 * t4 + s5 * t5;
    double lambda = std::sqrt(3.0 * squared_norm);
    for (int it = 0; it < 50; ++it) {
        const double l2 = lambda * lambda;
        const double value = (l2 + c2) * l2 + c1 * lambda + c0;
        const double slope = (4.0 * l2 + 2.0 * c2) * lambda + c1;
        if (!(slope > 0.0))
            break;
        const double step = value / slope;
        lambda -= step;
        if (std::abs(step) <= 1e-13 * lambda)
            break;
    }
    // adj(B) for B = N − λI: its diagonal is μ qᵢ², so the column of the largest diagonal entry
    // is the best conditioned multiple of q.
    double b[4][4];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            b[i][j] = n[i][j] - (i == j ? lambda : 0.0);
    static constexpr int others[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    auto cofactor = [&](int row, int col) {
        const int* r = others[row];
        const int* c = others[col];
        const double minor = b[r[0]][c[0]] * (b[r[1]][c[1]] * b[r[2]][c[2]] - b[r[1]][c[2]] * b[r[2]][c[1]]) -
                             b[r[0]][c[1]] * (b[r[1]][c[0]] * b[r[2]][c[2]] - b[r[1]][c[2]] * b[r[2]][c[0]]) +
                             b[r[0]][c[2]] * (b[r[1]][c[0]] * b[r[2]][c[1]] - b[r[1]][c[1]] * b[r[2]][c[0]]);
        return (row + col) % 2 == 0 ? minor : -minor;
    };
    double diagonal[4];
    int column = 0;
    for (int i = 0; i < 4; ++i) {
        diagonal[i] = cofactor(i, i);
        if (std::abs(diagonal[i]) > std::abs(diagonal[column]))
            column = i;
    }
    Eigen::Vector4d q;
    for (int i = 0; i < 4; ++i)
        q(i) = i == column ? diagonal[i] : cofactor(i, column);
    // Accept q only where it is provably close to the eigenvector (Davis–Kahan): its angle is
    // at most ‖B q̂‖ / gap, and the gap to the next eigenvalue is at least |μ| / (2√3‖a‖)²,
    // |μ| = Πₖ (λ − λₖ) over the three other eigenvalues being at most ‖q‖. Near a double
    // largest eigenvalue (a of rank one, rounded) Newton's λ and so q are not to be trusted.
    const double raw_norm = q.norm();
    q /= raw_norm;
    double residual = 0.0;
    for (int i = 0; i < 4; ++i) {
        const double bq = b[i][0] * q(0) + b[i][1] * q(1) + b[i][2] * q(2) + b[i][3] * q(3);
        residual += bq * bq;
    }
    if (!(std::sqrt(residual) * 12.0 * squared_norm <= 1e-9 * raw_norm))
        return false;
    const double w = q(0), x = q(1), y = q(2), z = q(3);
    rotation << w * w + x * x - y * y - z * z, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y), //
        2.0 * (x * y + w * z), w * w - x * x + y * y - z * z, 2.0 * (y * z - w * x),      //
        2.0 * (x * z - w * y), 2.0 * (y * z + w * x), w * w - x * x - y * y + z * z;
    return true;
}

/// The rotation R maximising tr(Rᵀa): Horn's method where it is provably accurate, else the SVD.
inline Eigen::Matrix3d best_rotation(const Eigen::Matrix3d& a)
{
    Eigen::Matrix3d rotation;
    return best_rotation_horn(a, rotation) ? rotation : best_rotation_svd(a);
}

} // namespace lobe
