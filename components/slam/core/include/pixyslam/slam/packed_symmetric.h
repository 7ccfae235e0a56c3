#pragma once

#include <vector>

#include <Eigen/Core>

namespace pixyslam::slam {

// A symmetric n x n matrix stored as its lower triangle, column after column
// (LAPACK's lower packed format): column c holds rows c..n-1 contiguously, so
// the whole matrix is n (n + 1) / 2 consecutive doubles. An update that
// touches every entry then streams one block of memory, half the bytes of
// dense storage, with no gaps for the hardware prefetcher to trip on.
class PackedSymmetric {
 public:
  using Segment = Eigen::Map<Eigen::VectorXd>;
  using ConstSegment = Eigen::Map<const Eigen::VectorXd>;

  PackedSymmetric() = default;
  // From the lower triangle of a square matrix.
  explicit PackedSymmetric(const Eigen::MatrixXd& m) { assign(m); }

  Eigen::Index size() const { return n_; }  // rows == columns
  // Entry (r, c) with r >= c.
  double& lower(Eigen::Index r, Eigen::Index c) { return data_[index(r, c)]; }
  double lower(Eigen::Index r, Eigen::Index c) const { return data_[index(r, c)]; }
  // Entry (r, c) on either side of the diagonal.
  double operator()(Eigen::Index r, Eigen::Index c) const { return r >= c ? lower(r, c) : lower(c, r); }
  // Rows `from`..n-1 of column c (from >= c).
  Segment column(Eigen::Index c, Eigen::Index from) { return Segment(&data_[index(from, c)], n_ - from); }
  ConstSegment column(Eigen::Index c, Eigen::Index from) const {
    return ConstSegment(&data_[index(from, c)], n_ - from);
  }
  // The k x k block on the diagonal at (i, i), both triangles.
  template <int K>
  Eigen::Matrix<double, K, K> diagonal_block(Eigen::Index i) const {
    Eigen::Matrix<double, K, K> b;
    for (int c = 0; c < K; ++c) {
      for (int r = c; r < K; ++r) b(r, c) = b(c, r) = lower(i + r, i + c);
    }
    return b;
  }
  // Sets that block from the lower triangle of symmetric b.
  template <int K>
  void set_diagonal_block(Eigen::Index i, const Eigen::Matrix<double, K, K>& b) {
    for (int c = 0; c < K; ++c) {
      for (int r = c; r < K; ++r) lower(i + r, i + c) = b(r, c);
    }
  }

  void assign(const Eigen::MatrixXd& m);  // the lower triangle of square m
  Eigen::MatrixXd full() const;           // both triangles
  // Adds `by` rows and columns of zeros at the end.
  void grow(Eigen::Index by);
  void clear() {
    data_.clear();
    n_ = 0;
  }
  const std::vector<double>& packed() const { return data_; }
  bool operator==(const PackedSymmetric& other) const { return n_ == other.n_ && data_ == other.data_; }

 private:
  // Column c starts after columns 0..c-1, of n, n-1, ... entries.
  std::size_t index(Eigen::Index r, Eigen::Index c) const {
    return static_cast<std::size_t>(c * n_ - c * (c - 1) / 2 + (r - c));
  }

  std::vector<double> data_;
  Eigen::Index n_ = 0;
};

}  // namespace pixyslam::slam
