#include "pixyslam/slam/landmark_map.h"

#include <stdexcept>

namespace pixyslam::slam {

struct LandmarkMap::Node {
  std::uint32_t refs = 1;
  bool is_leaf = false;
};

namespace {

using Node = LandmarkMap::Node;

struct Inner : Node {
  Node* child[2] = {nullptr, nullptr};
};

struct Leaf : Node {
  Landmark landmark;
};

Inner* inner(Node* n) { return static_cast<Inner*>(n); }
const Inner* inner(const Node* n) { return static_cast<const Inner*>(n); }
Leaf* leaf(Node* n) { return static_cast<Leaf*>(n); }
const Leaf* leaf(const Node* n) { return static_cast<const Leaf*>(n); }

constexpr std::size_t kBlockNodes = 4096;
constexpr int kMaxDepth = 31;

void ref(Node* n) {
  if (n) ++n->refs;
}

// Drops one reference; frees the nodes that become unreferenced. Recursion depth
// is the tree depth (at most 31).
void unref(LandmarkMapPool* pool, Node* n, void (*free_node)(LandmarkMapPool*, Node*)) {
  if (!n || --n->refs > 0) return;
  if (!n->is_leaf) {
    unref(pool, inner(n)->child[0], free_node);
    unref(pool, inner(n)->child[1], free_node);
  }
  free_node(pool, n);
}

template <class T>
Node* take(std::vector<Node*>& free_list, std::vector<std::shared_ptr<void>>& blocks, std::size_t& used) {
  T* n;
  if (!free_list.empty()) {
    n = static_cast<T*>(free_list.back());
    free_list.pop_back();
  } else {
    if (blocks.empty() || used == kBlockNodes) {
      blocks.emplace_back(new T[kBlockNodes], std::default_delete<T[]>());
      used = 0;
    }
    n = static_cast<T*>(blocks.back().get()) + used++;
  }
  *n = T{};
  return n;
}

}  // namespace

LandmarkMapPool::~LandmarkMapPool() = default;

LandmarkMap::Node* LandmarkMapPool::allocate(bool is_leaf) {
  ++allocated_total_;
  ++live_;
  Node* n = is_leaf ? take<Leaf>(leaf_.free_list, leaf_.blocks, leaf_.block_used)
                    : take<Inner>(inner_.free_list, inner_.blocks, inner_.block_used);
  n->is_leaf = is_leaf;
  return n;
}

void LandmarkMapPool::free(LandmarkMap::Node* node) {
  --live_;
  (node->is_leaf ? leaf_ : inner_).free_list.push_back(node);
}

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
  for (int level = depth_ - 1; level >= 0 && n; --level) n = inner(n)->child[(slot >> level) & 1u];
  return (n && n->is_leaf) ? &leaf(n)->landmark : nullptr;
}

Landmark& LandmarkMap::modify(std::uint32_t slot) {
  if (!pool_) throw std::logic_error("LandmarkMap::modify on a map without a pool");
  if (!root_) {
    int depth = 0;
    while ((slot >> depth) != 0) {
      if (++depth > kMaxDepth) throw std::out_of_range("LandmarkMap slot too large");
    }
    depth_ = depth;
  }
  // Grow: the old tree becomes the left subtree of a new root until slot fits.
  while (root_ && (slot >> depth_) != 0) {
    if (depth_ >= kMaxDepth) throw std::out_of_range("LandmarkMap slot too large");
    Node* top = pool_->allocate(false);
    inner(top)->child[0] = root_;
    root_ = top;
    ++depth_;
  }
  // Walk down, unsharing every node on the path that another map also holds.
  Node** link = &root_;
  for (int level = depth_;; --level) {
    Node* n = *link;
    if (!n) {
      n = pool_->allocate(level == 0);
      if (n->is_leaf) ++size_;
      *link = n;
    } else {
      n = own(link);
    }
    if (level == 0) return leaf(n)->landmark;
    link = &inner(n)->child[(slot >> (level - 1)) & 1u];
  }
}

Landmark* LandmarkMap::modify_if_present(std::uint32_t slot) {
  if (!root_ || (slot >> depth_) != 0) return nullptr;
  // Check first without copying, so an absent slot costs no allocation.
  if (!find(slot)) return nullptr;
  Node** link = &root_;
  for (int level = depth_;; --level) {
    Node* n = own(link);
    if (level == 0) return &leaf(n)->landmark;
    link = &inner(n)->child[(slot >> (level - 1)) & 1u];
  }
}

LandmarkMap::Node* LandmarkMap::own(Node** link) {
  Node* n = *link;
  if (n->refs == 1) return n;
  Node* copy = pool_->allocate(n->is_leaf);
  if (n->is_leaf) {
    leaf(copy)->landmark = leaf(n)->landmark;
  } else {
    for (Node* c : inner(n)->child) {
      ref(c);
    }
    inner(copy)->child[0] = inner(n)->child[0];
    inner(copy)->child[1] = inner(n)->child[1];
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
      visit(it.prefix, leaf(it.node)->landmark);
      continue;
    }
    stack.push_back({inner(it.node)->child[1], it.level - 1, (it.prefix << 1) | 1u});
    stack.push_back({inner(it.node)->child[0], it.level - 1, it.prefix << 1});
  }
}

bool LandmarkMap::shares_node_with(const LandmarkMap& other, std::uint32_t slot) const {
  const Landmark* a = find(slot);
  return a && a == other.find(slot);
}

}  // namespace pixyslam::slam
