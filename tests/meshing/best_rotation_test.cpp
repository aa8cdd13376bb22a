// The rotation fit of pinch editing (meshing/best_rotation.h): Horn's quaternion method,
// checked against the SVD on random and degenerate correlation matrices.
#include "meshing/best_rotation.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace {

using Eigen::Matrix3d;

Matrix3d random_matrix(std::mt19937& rng)
{
    std::normal_distribution<double> normal(0.0, 1.0);
    Matrix3d m;
    for (int i = 0; i < 9; ++i)
        m(i) = normal(rng);
    return m;
}

Matrix3d random_rotation(std::mt19937& rng)
{
    std::normal_distribution<double> normal(0.0, 1.0);
    const Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
    return Eigen::AngleAxisd(3.0 * normal(rng), axis.normalized()).toRotationMatrix();
}

bool is_rotation(const Matrix3d& r)
{
    return (r.transpose() * r - Matrix3d::Identity()).norm() < 1e-12 && std::abs(r.determinant() - 1.0) < 1e-12;
}

/// Correlation matrices of every kind the fit can meet: near rotations with stretch (what a
/// pinch frame gives), random ones (half of them reflections), rank two and rank one plus a
/// little, over scales from 1e-9 to 1e6.
Matrix3d random_case(std::mt19937& rng, int k)
{
    const double scale = std::pow(10.0, double(k % 16) - 9.0);
    switch (k % 4) {
    case 0:
        return scale * random_rotation(rng) * (Matrix3d::Identity() + 0.3 * random_matrix(rng));
    case 1:
        return scale * random_matrix(rng);
    case 2: {
        const Matrix3d m = random_matrix(rng);
        const Eigen::Vector3d n = m.col(0).cross(m.col(1));
        return scale * (m - (m * n) * n.transpose() / n.squaredNorm()); // rank two
    }
    default: {
        const Matrix3d m = random_matrix(rng);
        return scale * (m.col(0) * m.col(1).transpose() + std::pow(10.0, -double(k % 13)) * m.col(2) * m.row(2));
    }
    }
}

TEST(BestRotation, IsAProperRotationAtLeastAsGoodAsTheSvdsForEveryMatrix)
{
    std::mt19937 rng(7);
    for (int k = 0; k < 40000; ++k) {
        const Matrix3d a = random_case(rng, k);
        const Matrix3d r = lobe::best_rotation(a);
        ASSERT_TRUE(is_rotation(r)) << "case " << k << "\n" << a;
        const Matrix3d svd = lobe::best_rotation_svd(a);
        // tr(Rᵀa) is what the fit maximises; the SVD's rotation is the optimum.
        EXPECT_GE((r.transpose() * a).trace(), (svd.transpose() * a).trace() - 1e-12 * a.norm())
            << "case " << k << "\n" << a;
    }
}

TEST(BestRotation, HornEqualsTheSvdWhereverTheRotationIsDetermined)
{
    std::mt19937 rng(11);
    int compared = 0;
    for (int k = 0; k < 40000; ++k) {
        const Matrix3d a = random_case(rng, k);
        const Eigen::Vector3d sigma = Eigen::JacobiSVD<Matrix3d>(a).singularValues();
        // The gap between N's two largest eigenvalues: 2(σ₂ ± σ₃), the sign of det a.
        const double gap = a.determinant() >= 0.0 ? sigma(1) + sigma(2) : sigma(1) - sigma(2);
        if (!(gap > 1e-3 * sigma(0)))
            continue;
        Matrix3d horn;
        ASSERT_TRUE(lobe::best_rotation_horn(a, horn)) << "case " << k << "\n" << a;
        EXPECT_LT((horn - lobe::best_rotation_svd(a)).norm(), 1e-8) << "case " << k << "\n" << a;
        ++compared;
    }
    EXPECT_GT(compared, 25000);
}

TEST(BestRotation, HornTakesEveryStretchedNearRotation)
{
    // What a pinch frame fits: rest edges against the same edges rotated and stretched by up
    // to ±30 %. These must take the fast path, or the frame time is the SVD's.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> stretch(0.7, 1.3);
    for (int k = 0; k < 20000; ++k) {
        const Matrix3d rotation = random_rotation(rng);
        const Matrix3d rest = random_matrix(rng);
        const Eigen::Vector3d s(stretch(rng), stretch(rng), stretch(rng));
        const Matrix3d a = rotation * s.asDiagonal() * rest * rest.transpose();
        if (a.determinant() <= 0.0)
            continue;
        Matrix3d horn;
        ASSERT_TRUE(lobe::best_rotation_horn(a, horn)) << "case " << k << "\n" << a;
        EXPECT_LT((horn - lobe::best_rotation_svd(a)).norm(), 1e-8);
    }
}

TEST(BestRotation, DegenerateOrNonFiniteMatricesGoToTheSvd)
{
    Matrix3d horn;
    EXPECT_FALSE(lobe::best_rotation_horn(Matrix3d::Zero(), horn));
    const Eigen::Vector3d u(1.0, 2.0, 3.0), v(-2.0, 0.5, 1.0);
    // Rank one: every rotation taking v's direction to u's is as good, so none is trusted.
    EXPECT_FALSE(lobe::best_rotation_horn(u * v.transpose(), horn));
    Matrix3d nan = Matrix3d::Identity();
    nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(lobe::best_rotation_horn(nan, horn));
    EXPECT_TRUE(is_rotation(lobe::best_rotation(u * v.transpose())));
    // A reflection: the best proper rotation gives up the least certain axis, here the
    // identity (tr = 3 + 2 − 1), as the SVD does.
    const Matrix3d reflection = Eigen::Vector3d(3.0, 2.0, -1.0).asDiagonal();
    ASSERT_TRUE(lobe::best_rotation_horn(reflection, horn));
    EXPECT_LT((horn - Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_LT((lobe::best_rotation_svd(reflection) - Matrix3d::Identity()).norm(), 1e-12);
}

} // namespace
