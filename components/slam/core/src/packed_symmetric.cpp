#include "pixyslam/slam/packed_symmetric.h"

namespace pixyslam::slam {

void PackedSymmetric::assign(const Eigen::MatrixXd& m) {
  n_ = m.rows();
  data_.resize(static_cast<std::size_t>(n_ * (n_ + 1) / 2));
  for (Eigen::Index c = 0; c < n_; ++c) column(c, c) = m.col(c).tail(n_ - c);
}

Eigen::MatrixXd PackedSymmetric::full() const {
  Eigen::MatrixXd m(n_, n_);
  for (Eigen::Index c = 0; c < n_; ++c) {
    m.col(c).tail(n_ - c) = column(c, c);
    m.row(c).tail(n_ - c) = column(c, c).transpose();
  }
  return m;
}

void PackedSymmetric::grow(Eigen::Index by) {
  if (by <= 0) return;
  PackedSymmetric bigger;
  bigger.n_ = n_ + by;
  bigger.data_.assign(static_cast<std::size_t>(bigger.n_ * (bigger.n_ + 1) / 2), 0.0);
  for (Eigen::Index c = 0; c < n_; ++c) bigger.column(c, c).head(n_ - c) = column(c, c);
  *this = std::move(bigger);
}

}  // namespace pixyslam::slam
