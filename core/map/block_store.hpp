#pragma once
// Sparse storage of voxel blocks: an open-addressing (linear probing) hash map from packed block
// coordinate to a shared block. Blocks are shared with snapshots and copied on write.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/map/voxel_block.hpp"

namespace storey::core::map {

class BlockStore {
 public:
  BlockStore() { slots_.resize(1024); }
  // Copy = snapshot: shares every block (reference counts only, no cell copied).
  BlockStore(const BlockStore&) = default;
  BlockStore& operator=(const BlockStore&) = default;
  BlockStore(BlockStore&&) noexcept = default;
  BlockStore& operator=(BlockStore&&) noexcept = default;

  const VoxelBlock* find(uint64_t key) const {
    size_t i = hash(key) & (slots_.size() - 1);
    while (true) {
      const Slot& s = slots_[i];
      if (!s.block) return nullptr;
      if (s.key == key) return s.block.get();
      i = (i + 1) & (slots_.size() - 1);
    }
  }

  // Owner only. Returns a block this store owns exclusively, creating it if absent, or
  // nullptr if `create` is false and it is absent. A block still shared with a snapshot is
  // cloned first (copy-on-write): any pointer to the previous block obtained from this store is
  // then stale, which is why callers cache at most one write pointer and drop it on snapshot().
  VoxelBlock* find_mutable(uint64_t key, int32_t bx, int32_t by, int32_t bz, bool create) {
    size_t i = hash(key) & (slots_.size() - 1);
    while (true) {
      Slot& s = slots_[i];
      if (!s.block) break;
      if (s.key == key) {
        if (s.block.use_count() > 1) {  // only snapshots can hold another reference
          s.block = std::make_shared<VoxelBlock>(*s.block);
          ++cow_copies_;
        }
        return s.block.get();
      }
      i = (i + 1) & (slots_.size() - 1);
    }
    if (!create) return nullptr;
    if ((count_ + 1) * 2 > slots_.size()) {  // load factor <= 0.5
      grow();
      return find_mutable(key, bx, by, bz, create);
    }
    Slot& s = slots_[i];
    s.key = key;
    s.block = std::make_shared<VoxelBlock>();
    s.block->bx = bx;
    s.block->by = by;
    s.block->bz = bz;
    ++count_;
    return s.block.get();
  }

  template <class F>
  void for_each(F&& f) const {
    for (const Slot& s : slots_)
      if (s.block) f(*s.block);
  }
  // Owner only: iterate with write access (copy-on-write applied per block).
  template <class F>
  void for_each_mutable(F&& f) {
    for (Slot& s : slots_) {
      if (!s.block) continue;
      if (s.block.use_count() > 1) {
        s.block = std::make_shared<VoxelBlock>(*s.block);
        ++cow_copies_;
      }
      f(*s.block);
    }
  }

  size_t block_count() const { return count_; }
  uint64_t cow_copies() const { return cow_copies_; }
  // Bytes held: the slot table plus every block (shared blocks counted in full).
  size_t mem_usage() const {
    size_t bytes = sizeof(*this) + slots_.capacity() * sizeof(Slot);
    for_each([&](const VoxelBlock& b) {
      bytes += b.mem_usage() + 16; /* control block */
    });
    return bytes;
  }

 private:
  struct Slot {
    uint64_t key = 0;
    std::shared_ptr<VoxelBlock> block;
  };
  static size_t hash(uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return size_t(k);
  }
  void grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    slots_.resize(old.size() * 2);
    for (Slot& s : old) {
      if (!s.block) continue;
      size_t i = hash(s.key) & (slots_.size() - 1);
      while (slots_[i].block) i = (i + 1) & (slots_.size() - 1);
      slots_[i] = std::move(s);
    }
  }

  std::vector<Slot> slots_;
  size_t count_ = 0;
  uint64_t cow_copies_ = 0;
};

}  // namespace storey::core::map
