#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace pixyslam::slam {

// One landmark EKF of one particle: mean [m] and 2x2 covariance [m^2] in the map frame.
struct Landmark {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity();
  int id = 0;
  std::uint32_t times_observed = 0;
  std::uint32_t consecutive_rejections = 0;  // Mahalanobis gate, see FilterOptions
};

class LandmarkMapPool;

// A particle's landmarks, keyed by a dense slot index, stored in a persistent
// complete binary tree (Montemerlo et al., FastSLAM, Sec. "efficient
// implementation"): copying a map copies one pointer; changing one landmark copies
// only the O(log K) nodes on its path that are shared with other maps (nodes owned
// by this map alone are changed in place). Nodes are reference counted without
// atomics and recycled by a LandmarkMapPool, which must outlive every map made from
// it. Thread-compatible: maps sharing a pool must be used from one thread.
class LandmarkMap {
 public:
  explicit LandmarkMap(LandmarkMapPool* pool = nullptr);
  LandmarkMap(const LandmarkMap& other);
  LandmarkMap(LandmarkMap&& other) noexcept;
  LandmarkMap& operator=(const LandmarkMap& other);
  LandmarkMap& operator=(LandmarkMap&& other) noexcept;
  ~LandmarkMap();

  // nullptr when the slot holds no landmark.
  const Landmark* find(std::uint32_t slot) const;
  // Writable landmark in `slot` (created default if absent), unshared first.
  Landmark& modify(std::uint32_t slot);
  // Writable landmark in `slot` if present, else nullptr; one walk down the tree.
  // Pointers returned stay valid until this map is copied into, assigned or
  // destroyed (later modify calls on other slots do not move them).
  Landmark* modify_if_present(std::uint32_t slot);
  std::size_t size() const { return size_; }
  int depth() const { return depth_; }
  // Visits landmarks in slot order.
  void for_each(const std::function<void(std::uint32_t slot, const Landmark&)>& visit) const;
  // True if both maps reach the very same node for `slot` (no copy was made).
  bool shares_node_with(const LandmarkMap& other, std::uint32_t slot) const;
  // True if both maps are the very same tree (one is an unchanged copy of the other).
  bool same_tree_as(const LandmarkMap& other) const { return root_ == other.root_ && pool_ == other.pool_; }

  struct Node;  // opaque tree node

 private:
  friend class LandmarkMapPool;
  void release();
  // Unshares `*link` (copies it if another map holds it) and returns it.
  Node* own(Node** link);

  LandmarkMapPool* pool_ = nullptr;
  Node* root_ = nullptr;
  int depth_ = 0;  // leaves sit at this depth; capacity 2^depth
  std::size_t size_ = 0;
};

// Node storage for LandmarkMap with a free list; counts allocations so tests and
// benchmarks can see how many nodes an operation copied.
class LandmarkMapPool {
 public:
  LandmarkMapPool() = default;
  LandmarkMapPool(const LandmarkMapPool&) = delete;
  LandmarkMapPool& operator=(const LandmarkMapPool&) = delete;
  ~LandmarkMapPool();

  std::size_t nodes_allocated_total() const { return allocated_total_; }
  std::size_t nodes_live() const { return live_; }

 private:
  friend class LandmarkMap;
  // Inner nodes (two child pointers) and leaves (one Landmark) come from separate
  // slabs so the nodes walked on every lookup stay small.
  LandmarkMap::Node* allocate(bool leaf);
  void free(LandmarkMap::Node* node);

  struct Slab {
    std::vector<LandmarkMap::Node*> free_list;
    std::vector<std::shared_ptr<void>> blocks;  // owns the memory, typed deleter
    std::size_t block_used = 0;
  };
  Slab inner_;
  Slab leaf_;
  std::size_t allocated_total_ = 0;
  std::size_t live_ = 0;
};

}  // namespace pixyslam::slam
