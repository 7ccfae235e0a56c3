#include "pixyslam/slam/landmark_map.h"

#include <cassert>
#include <stdexcept>

namespace pixyslam::slam {

struct LandmarkMap::Node {
  std::uint32_t refs = 1;
  bool is_leaf = false;
  Node* child[2] = {nullptr, nullptr};
  Landmark landmark;
};

namespace {
constexpr std::size_t kBlockNodes = 4096;
constexpr int kMaxDepth = 31;
}  // namespace

LandmarkMapPool::~LandmarkMapPool() {
  for (LandmarkMap::Node* block : blocks_) delete[] block;
}

LandmarkMap::Node* LandmarkMapPool::allocate() {
  ++allocated_total_;
  ++live_;
  LandmarkMap::Node* n;
  if (!free_list_.empty()) {
    n = free_list_.back();
    free_list_.pop_back();
  } else {
    if (blocks_.empty() || block_used_ == kBlockNodes) {
      blocks_.push_back(new LandmarkMap::Node[kBlockNodes]);
      block_used_ = 0;
    }
    n = &blocks_.back()[block_used_++];
  }
  *n = LandmarkMap::Node{};
  return n;
}

void LandmarkMapPool::free(LandmarkMap::Node* node) {
  --live_;
  free_list_.push_back(node);
}

namespace {

using Node = LandmarkMap::Node;

void ref(Node* n) {
  if (n) ++n->refs;
}

// Drops one reference; frees the nodes that become unreferenced. Recursion depth
// is the tree depth (at most 31).
void unref(LandmarkMapPool* pool, Node* n, void (*free_node)(LandmarkMapPool*, Node*)) {
  if (!n || --n->refs > 0) return;
  if (!n->is_leaf) {
    unref(pool, n->child[0], free_node);
    unref(pool, n->child[1], free_node);
  }
  free_node(pool, n);
}

}  // namespace

LandmarkMap::LandmarkMap(LandmarkMapPool* pool) : pool_(pool) {}

LandmarkMap::LandmarkMap(const LandmarkMap& other)
    : pool_(other.pool_), root_(other.root_), depth_(other.depth_), size_(other.size_) {
  ref(root_);
}

LandmarkMap::LandmarkMap(LandmarkMap&& other) noexcept
    : pool_(other.pool_), root_(other.root_), depth_(other.depth_), size_(other.size_) {
  other.root_ = nullptr;
  other.depth_ = 0;
  other.size_ = 0;
}

LandmarkMap& LandmarkMap::operator=(const LandmarkMap& other) {
  if (this == &other) return *this;
  ref(other.root_);
  release();
  pool_ = other.pool_;
  root_ = other.root_;
  depth_ = other.depth_;
  size_ = other.size_;
  return *this;
}

LandmarkMap& LandmarkMap::operator=(LandmarkMap&& other) noexcept {
  if (this == &other) return *this;
  release();
  pool_ = other.pool_;
  root_ = other.root_;
  depth_ = other.depth_;
  size_ = other.size_;
  other.root_ = nullptr;
  other.depth_ = 0;
  other.size_ = 0;
  return *this;
}

LandmarkMap::~LandmarkMap() { release(); }

void LandmarkMap::release() {
  if (!root_) return;
  unref(pool_, root_, [](LandmarkMapPool* p, Node* n) { p->free(n); });
  root_ = nullptr;
}

const Landmark* LandmarkMap::find(std::uint32_t slot) const {
  if (!root_ || (depth_ < 32 && (slot >> depth_) != 0)) return nullptr;
  const Node* n = root_;
  for (int level = depth_ - 1; level >= 0 && n; --level) n = n->child[(slot >> level) & 1u];
  return (n && n->is_leaf) ? &n->landmark : nullptr;
}

Landmark& LandmarkMap::modify(std::uint32_t slot) {
  if (!pool_) throw std::logic_error("LandmarkMap::modify on a map without a pool");
  if (!root_) {
    depth_ = 0;
    while ((slot >> depth_) != 0) ++depth_;
  }
  // Grow: the old tree becomes the left subtree of a new root until slot fits.
  while (root_ && (slot >> depth_) != 0) {
    if (depth_ >= kMaxDepth) throw std::out_of_range("LandmarkMap slot too large");
    Node* top = pool_->allocate();
    top->child[0] = root_;
    root_ = top;
    ++depth_;
  }
  // Walk down, unsharing every node on the path that another map also holds.
  Node** link = &root_;
  for (int level = depth_;; --level) {
    Node* n = *link;
    if (!n) {
      n = pool_->allocate();
      n->is_leaf = (level == 0);
      if (n->is_leaf) ++size_;
      *link = n;
    } else {
      n = own(link);
    }
    if (level == 0) return n->landmark;
    link = &n->child[(slot >> (level - 1)) & 1u];
  }
}

Landmark* LandmarkMap::modify_if_present(std::uint32_t slot) {
  if (!root_ || (slot >> depth_) != 0) return nullptr;
  // Check first without copying, so an absent slot costs no allocation.
  if (!find(slot)) return nullptr;
  Node** link = &root_;
  for (int level = depth_;; --level) {
    Node* n = own(link);
    if (level == 0) return &n->landmark;
    link = &n->child[(slot >> (level - 1)) & 1u];
  }
}

LandmarkMap::Node* LandmarkMap::own(Node** link) {
  Node* n = *link;
  if (n->refs == 1) return n;
  Node* copy = pool_->allocate();
  *copy = *n;
  copy->refs = 1;
  if (!n->is_leaf) {
    ref(copy->child[0]);
    ref(copy->child[1]);
  }
  --n->refs;
  *link = copy;
  return copy;
}

void LandmarkMap::for_each(const std::function<void(std::uint32_t, const Landmark&)>& visit) const {
  if (!root_) return;
  struct Item {
    const Node* node;
    int level;
    std::uint32_t prefix;
  };
  std::vector<Item> stack{{root_, depth_, 0}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (!it.node) continue;
    if (it.level == 0) {
      visit(it.prefix, it.node->landmark);
      continue;
    }
    stack.push_back({it.node->child[1], it.level - 1, (it.prefix << 1) | 1u});
    stack.push_back({it.node->child[0], it.level - 1, it.prefix << 1});
  }
}

bool LandmarkMap::shares_node_with(const LandmarkMap& other, std::uint32_t slot) const {
  const Landmark* a = find(slot);
  return a && a == other.find(slot);
}

}  // namespace pixyslam::slam
