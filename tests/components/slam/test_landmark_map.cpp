// Tests of the copy-on-write persistent landmark tree: sharing, path copying,
// node accounting, growth, ordered iteration, and a randomized comparison against
// a std::map model over many map handles.

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/slam/landmark_map.h"

namespace pixyslam::slam {
namespace {

// Marks a landmark with a value derived from its slot so leaks are visible.
void put(LandmarkMap& m, std::uint32_t slot, double value) {
  Landmark& lm = m.modify(slot);
  lm.mean.x() = value;
  lm.id = static_cast<int>(slot);
}

double value_of(const LandmarkMap& m, std::uint32_t slot) {
  const Landmark* lm = m.find(slot);
  return lm ? lm->mean.x() : -1.0;
}

TEST(LandmarkMap, EmptyMapFindsNothing) {
  LandmarkMapPool pool;
  const LandmarkMap m(&pool);
  EXPECT_EQ(m.size(), 0u);
  EXPECT_EQ(m.find(0), nullptr);
  EXPECT_EQ(m.find(12345), nullptr);
  int visits = 0;
  m.for_each([&](std::uint32_t, const Landmark&) { ++visits; });
  EXPECT_EQ(visits, 0);
  EXPECT_EQ(pool.nodes_live(), 0u);
}

TEST(LandmarkMap, ModifyWithoutPoolThrows) {
  LandmarkMap m;
  EXPECT_THROW(m.modify(0), std::logic_error);
}

TEST(LandmarkMap, InsertManyAndFindThem) {
  LandmarkMapPool pool;
  LandmarkMap m(&pool);
  for (std::uint32_t s = 0; s < 300; ++s) put(m, s, 1000.0 + s);
  EXPECT_EQ(m.size(), 300u);
  // 300 slots need 2^9 = 512 capacity.
  EXPECT_EQ(m.depth(), 9);
  for (std::uint32_t s = 0; s < 300; ++s) {
    const Landmark* lm = m.find(s);
    ASSERT_NE(lm, nullptr) << s;
    EXPECT_EQ(lm->mean.x(), 1000.0 + s);
    EXPECT_EQ(lm->id, static_cast<int>(s));
  }
  EXPECT_EQ(m.find(300), nullptr);
  EXPECT_EQ(m.find(511), nullptr);
  EXPECT_EQ(m.find(512), nullptr);
  EXPECT_EQ(m.find(1u << 30), nullptr);
  // A fresh landmark has the documented defaults.
  Landmark& fresh = m.modify(400);
  EXPECT_EQ(fresh.times_observed, 0u);
  EXPECT_EQ(fresh.consecutive_rejections, 0u);
  EXPECT_EQ(fresh.cov, Eigen::Matrix2d::Identity());
  EXPECT_EQ(m.size(), 301u);
}

TEST(LandmarkMap, ModifyExistingSlotDoesNotGrowSize) {
  LandmarkMapPool pool;
  LandmarkMap m(&pool);
  put(m, 5, 1.0);
  put(m, 5, 2.0);
  EXPECT_EQ(m.size(), 1u);
  EXPECT_EQ(value_of(m, 5), 2.0);
}

TEST(LandmarkMap, CopySharesEveryNodeAndAllocatesNothing) {
  LandmarkMapPool pool;
  LandmarkMap a(&pool);
  for (std::uint32_t s = 0; s < 100; ++s) put(a, s, s);
  const std::size_t allocated = pool.nodes_allocated_total();
  const std::size_t live = pool.nodes_live();

  const LandmarkMap b(a);  // copy construction
  LandmarkMap c(&pool);
  c = a;                   // copy assignment
  EXPECT_EQ(pool.nodes_allocated_total(), allocated);
  EXPECT_EQ(pool.nodes_live(), live);
  EXPECT_EQ(b.size(), a.size());
  EXPECT_EQ(b.depth(), a.depth());
  for (std::uint32_t s = 0; s < 100; ++s) {
    EXPECT_TRUE(b.shares_node_with(a, s)) << s;
    EXPECT_TRUE(c.shares_node_with(a, s)) << s;
  }
  // Absent slots are never "shared".
  EXPECT_FALSE(b.shares_node_with(a, 100));
}

TEST(LandmarkMap, ModifyingACopyCopiesOnlyThePath) {
  LandmarkMapPool pool;
  LandmarkMap original(&pool);
  for (std::uint32_t s = 0; s < 200; ++s) put(original, s, s);
  LandmarkMap copy(original);
  const int depth = copy.depth();
  ASSERT_EQ(depth, 8);

  // When one slot of the copy is modified,
  const std::size_t before = pool.nodes_allocated_total();
  put(copy, 77, -5.0);
  const std::size_t copied = pool.nodes_allocated_total() - before;
  // then only the root-to-leaf path is copied,
  EXPECT_GE(copied, 1u);
  EXPECT_LE(copied, static_cast<std::size_t>(depth + 1));
  // the original keeps its value (no leak between particles),
  EXPECT_EQ(value_of(original, 77), 77.0);
  EXPECT_EQ(value_of(copy, 77), -5.0);
  EXPECT_FALSE(copy.shares_node_with(original, 77));
  // and every other slot is still shared.
  for (std::uint32_t s = 0; s < 200; ++s) {
    if (s != 77) {
      EXPECT_TRUE(copy.shares_node_with(original, s)) << s;
    }
  }

  // Modifying the same slot again touches only nodes the copy now owns alone.
  const std::size_t before_again = pool.nodes_allocated_total();
  put(copy, 77, -6.0);
  EXPECT_EQ(pool.nodes_allocated_total(), before_again);
  EXPECT_EQ(value_of(original, 77), 77.0);

  // A neighbouring slot shares most of that path: it copies at most depth nodes
  // (the root is already owned by the copy).
  const std::size_t before_neighbour = pool.nodes_allocated_total();
  put(copy, 76, -7.0);
  const std::size_t copied_neighbour = pool.nodes_allocated_total() - before_neighbour;
  EXPECT_GE(copied_neighbour, 1u);
  EXPECT_LE(copied_neighbour, static_cast<std::size_t>(depth));
  EXPECT_EQ(value_of(original, 76), 76.0);

  // Modifying the ORIGINAL after the copy does not leak into the copy either.
  put(original, 3, 333.0);
  EXPECT_EQ(value_of(copy, 3), 3.0);
  EXPECT_EQ(value_of(original, 3), 333.0);
  EXPECT_EQ(original.size(), 200u);
  EXPECT_EQ(copy.size(), 200u);
}

TEST(LandmarkMap, InsertingANewSlotIntoACopyDoesNotAppearInTheOriginal) {
  LandmarkMapPool pool;
  LandmarkMap a(&pool);
  for (std::uint32_t s = 0; s < 10; s += 2) put(a, s, s);
  LandmarkMap b(a);
  put(b, 1, 11.0);
  EXPECT_EQ(a.find(1), nullptr);
  EXPECT_EQ(a.size(), 5u);
  EXPECT_EQ(b.size(), 6u);
  EXPECT_EQ(value_of(b, 1), 11.0);
  for (std::uint32_t s = 0; s < 10; s += 2) EXPECT_TRUE(b.shares_node_with(a, s)) << s;
}

TEST(LandmarkMap, GrowthToLargeSlotsKeepsEarlierSlots) {
  LandmarkMapPool pool;
  LandmarkMap m(&pool);
  for (std::uint32_t s = 0; s < 10; ++s) put(m, s, 100.0 + s);
  LandmarkMap before_growth(m);
  put(m, 10000, 7.0);
  EXPECT_GE(m.depth(), 14);  // 2^14 = 16384 > 10000
  EXPECT_EQ(m.size(), 11u);
  EXPECT_EQ(value_of(m, 10000), 7.0);
  for (std::uint32_t s = 0; s < 10; ++s) {
    EXPECT_EQ(value_of(m, s), 100.0 + s) << s;
    // Growth adds levels above the old tree: the old leaves stay shared.
    EXPECT_TRUE(m.shares_node_with(before_growth, s)) << s;
  }
  EXPECT_EQ(m.find(9999), nullptr);
  EXPECT_EQ(m.find(10001), nullptr);
  // The snapshot taken before growth is unchanged.
  EXPECT_EQ(before_growth.find(10000), nullptr);
  EXPECT_EQ(before_growth.size(), 10u);
  EXPECT_LT(before_growth.depth(), m.depth());

  put(m, 1u << 20, 8.0);
  EXPECT_EQ(value_of(m, 1u << 20), 8.0);
  EXPECT_EQ(value_of(m, 10000), 7.0);
  EXPECT_EQ(value_of(m, 0), 100.0);

  // A map whose first slot is large, then small ones.
  LandmarkMap n(&pool);
  put(n, 5000, 1.0);
  put(n, 0, 2.0);
  put(n, 4999, 3.0);
  EXPECT_EQ(value_of(n, 5000), 1.0);
  EXPECT_EQ(value_of(n, 0), 2.0);
  EXPECT_EQ(value_of(n, 4999), 3.0);
  EXPECT_EQ(n.size(), 3u);
}

TEST(LandmarkMap, DestroyingMapsReturnsAllNodes) {
  LandmarkMapPool pool;
  {
    LandmarkMap a(&pool);
    for (std::uint32_t s = 0; s < 500; ++s) put(a, s, s);
    EXPECT_GT(pool.nodes_live(), 500u);
    std::vector<LandmarkMap> copies(20, a);
    for (std::size_t i = 0; i < copies.size(); ++i) put(copies[i], static_cast<std::uint32_t>(i * 7), -1.0);
    put(copies[3], 9000, 1.0);
    LandmarkMap moved(std::move(copies[5]));
    copies[6] = std::move(copies[7]);
    copies[8] = copies[9];
    copies[10] = copies[10];  // self-assignment keeps the map intact
    EXPECT_EQ(value_of(copies[10], 70), -1.0);
    EXPECT_EQ(value_of(moved, 35), -1.0);
    EXPECT_EQ(value_of(copies[6], 49), -1.0);
    EXPECT_EQ(value_of(copies[8], 63), -1.0);
    EXPECT_EQ(value_of(a, 63), 63.0);
  }
  EXPECT_EQ(pool.nodes_live(), 0u);

  // Freed nodes are reused: building the same map again allocates from the free
  // list and leaves nothing live afterwards.
  {
    LandmarkMap again(&pool);
    for (std::uint32_t s = 0; s < 500; ++s) put(again, s, s);
    EXPECT_EQ(value_of(again, 499), 499.0);
  }
  EXPECT_EQ(pool.nodes_live(), 0u);
}

TEST(LandmarkMap, ForEachVisitsInSlotOrder) {
  std::mt19937 prng(42);
  LandmarkMapPool pool;
  LandmarkMap m(&pool);
  std::vector<std::uint32_t> slots;
  std::uniform_int_distribution<std::uint32_t> pick(0, 5000);
  for (int i = 0; i < 300; ++i) slots.push_back(pick(prng));
  for (std::uint32_t s : slots) put(m, s, 2.0 * s);
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());

  std::vector<std::uint32_t> seen;
  m.for_each([&](std::uint32_t slot, const Landmark& lm) {
    seen.push_back(slot);
    EXPECT_EQ(lm.mean.x(), 2.0 * slot);
    EXPECT_EQ(lm.id, static_cast<int>(slot));
  });
  EXPECT_EQ(seen, slots);
  EXPECT_EQ(m.size(), slots.size());
}

// Checks one handle against its model: size, find of every key, and for_each.
void expect_matches(const LandmarkMap& m, const std::map<std::uint32_t, double>& model, int step, int handle) {
  ASSERT_EQ(m.size(), model.size()) << "step " << step << " handle " << handle;
  for (const auto& [slot, value] : model) {
    const Landmark* lm = m.find(slot);
    ASSERT_NE(lm, nullptr) << "step " << step << " handle " << handle << " slot " << slot;
    ASSERT_EQ(lm->mean.x(), value) << "step " << step << " handle " << handle << " slot " << slot;
  }
  auto it = model.begin();
  m.for_each([&](std::uint32_t slot, const Landmark& lm) {
    ASSERT_NE(it, model.end());
    EXPECT_EQ(slot, it->first);
    EXPECT_EQ(lm.mean.x(), it->second);
    ++it;
  });
  EXPECT_EQ(it, model.end()) << "step " << step << " handle " << handle;
}

TEST(LandmarkMap, RandomizedAgainstStdMapModel) {
  std::mt19937 prng(42);
  constexpr int kHandles = 8;
  LandmarkMapPool pool;
  {
    std::vector<std::unique_ptr<LandmarkMap>> maps;
    std::vector<std::map<std::uint32_t, double>> models(kHandles);
    for (int i = 0; i < kHandles; ++i) maps.push_back(std::make_unique<LandmarkMap>(&pool));

    std::uniform_int_distribution<int> op_dist(0, 99);
    std::uniform_int_distribution<int> handle_dist(0, kHandles - 1);
    std::uniform_int_distribution<std::uint32_t> small_slot(0, 150);
    std::uniform_int_distribution<std::uint32_t> big_slot(0, 20000);
    double next_value = 1.0;
    for (int step = 0; step < 4000; ++step) {
      const int op = op_dist(prng);
      const int h = handle_dist(prng);
      if (op < 60) {
        // modify (insert or overwrite); occasionally a far slot forces growth
        const std::uint32_t slot = op < 3 ? big_slot(prng) : small_slot(prng);
        const std::size_t before = pool.nodes_allocated_total();
        const int depth_before = maps[h]->depth();
        put(*maps[h], slot, next_value);
        models[h][slot] = next_value;
        next_value += 1.0;
        // Path copying bound: a new path plus growth levels, never more.
        const int new_depth = maps[h]->depth();
        EXPECT_LE(pool.nodes_allocated_total() - before,
                  static_cast<std::size_t>(new_depth + 1 + std::max(0, new_depth - depth_before)));
      } else if (op < 80) {
        // copy handle g into h (particle duplication in resampling)
        const int g = handle_dist(prng);
        const std::size_t before = pool.nodes_allocated_total();
        *maps[h] = *maps[g];
        models[h] = models[g];
        EXPECT_EQ(pool.nodes_allocated_total(), before);
        for (const auto& kv : models[h]) {
          if (g != h) {
            ASSERT_TRUE(maps[h]->shares_node_with(*maps[g], kv.first));
          }
        }
      } else if (op < 88) {
        // destroy h and start over empty
        maps[h] = std::make_unique<LandmarkMap>(&pool);
        models[h].clear();
      } else if (op < 94) {
        // copy-construct into a fresh handle object, replacing h
        const int g = handle_dist(prng);
        auto fresh = std::make_unique<LandmarkMap>(*maps[g]);
        maps[h] = std::move(fresh);
        models[h] = models[g];
      } else {
        // move-assign g into h, g becomes empty (moved-from maps stay usable)
        const int g = handle_dist(prng);
        if (g == h) continue;
        *maps[h] = std::move(*maps[g]);
        models[h] = std::move(models[g]);
        models[g].clear();
        EXPECT_EQ(maps[g]->size(), 0u);
      }
      for (int i = 0; i < kHandles; ++i) {
        expect_matches(*maps[i], models[i], step, i);
        if (HasFatalFailure()) return;
      }
    }
  }
  EXPECT_EQ(pool.nodes_live(), 0u);
}

TEST(LandmarkMap, ModifyIfPresentUnsharesOnlyPresentSlots) {
  LandmarkMapPool pool;
  LandmarkMap original(&pool);
  for (std::uint32_t s = 0; s < 100; s += 2) put(original, s, s);
  LandmarkMap copy(original);
  const int depth = copy.depth();

  // An absent slot (inside or beyond the capacity) gives nullptr, allocates nothing.
  const std::size_t before = pool.nodes_allocated_total();
  EXPECT_EQ(copy.modify_if_present(1), nullptr);
  EXPECT_EQ(copy.modify_if_present(99), nullptr);
  EXPECT_EQ(copy.modify_if_present(5000), nullptr);
  EXPECT_EQ(pool.nodes_allocated_total(), before);
  EXPECT_EQ(copy.size(), 50u);
  EXPECT_EQ(copy.find(1), nullptr);

  // A present slot is unshared along its path only; writing through the
  // pointer does not reach the original.
  Landmark* lm = copy.modify_if_present(42);
  ASSERT_NE(lm, nullptr);
  EXPECT_LE(pool.nodes_allocated_total() - before, static_cast<std::size_t>(depth + 1));
  lm->mean.x() = -42.0;
  EXPECT_EQ(value_of(copy, 42), -42.0);
  EXPECT_EQ(value_of(original, 42), 42.0);
  EXPECT_EQ(copy.size(), 50u);
  for (std::uint32_t s = 0; s < 100; s += 2) {
    if (s != 42) {
      EXPECT_TRUE(copy.shares_node_with(original, s)) << s;
    }
  }

  // The pointer stays valid while other slots of the same map are modified,
  // even when the tree grows.
  put(copy, 44, -44.0);
  put(copy, 43, -43.0);
  put(copy, 3000, -3000.0);
  lm->mean.y() = 7.0;
  ASSERT_NE(copy.find(42), nullptr);
  EXPECT_EQ(copy.find(42)->mean.y(), 7.0);
  EXPECT_EQ(copy.find(42), lm);
  EXPECT_EQ(original.find(42)->mean.y(), 0.0);
  EXPECT_EQ(original.find(3000), nullptr);

  // Already owned: a second call allocates nothing and returns the same landmark.
  const std::size_t owned = pool.nodes_allocated_total();
  EXPECT_EQ(copy.modify_if_present(42), lm);
  EXPECT_EQ(pool.nodes_allocated_total(), owned);

  LandmarkMap empty(&pool);
  EXPECT_EQ(empty.modify_if_present(0), nullptr);
  EXPECT_EQ(empty.size(), 0u);
}

TEST(LandmarkMap, SlotBeyondTheDepthLimitThrowsOnANonEmptyMap) {
  LandmarkMapPool pool;
  LandmarkMap m(&pool);
  put(m, 0, 1.0);
  EXPECT_THROW(m.modify(1u << 31), std::out_of_range);
  EXPECT_EQ(m.find(1u << 31), nullptr);
  EXPECT_EQ(value_of(m, 0), 1.0);  // the map is still intact
  put(m, (1u << 31) - 1, 2.0);      // the largest slot that fits
  EXPECT_EQ(value_of(m, (1u << 31) - 1), 2.0);
}

TEST(LandmarkMap, SlotBeyondTheDepthLimitThrowsOnAnEmptyMap) {
  // Regression: the first-insert depth loop used to shift by 32 (UB, a hang).
  LandmarkMapPool pool;
  LandmarkMap m(&pool);
  EXPECT_THROW(m.modify(1u << 31), std::out_of_range);
  EXPECT_EQ(m.size(), 0u);
}

TEST(LandmarkMap, MovedFromMapIsEmptyAndReusable) {
  LandmarkMapPool pool;
  LandmarkMap a(&pool);
  put(a, 3, 3.0);
  LandmarkMap b(std::move(a));
  EXPECT_EQ(value_of(b, 3), 3.0);
  EXPECT_EQ(a.size(), 0u);  // NOLINT(bugprone-use-after-move): documented state
  EXPECT_EQ(a.find(3), nullptr);
  put(a, 4, 4.0);
  EXPECT_EQ(value_of(a, 4), 4.0);
  EXPECT_EQ(b.find(4), nullptr);
}

}  // namespace
}  // namespace pixyslam::slam
