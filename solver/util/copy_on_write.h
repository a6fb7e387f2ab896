// A value held by pointer and shared by its copies until one of them changes it (copy on
// write): the nodes of a structure placed many times (a plantation of copies of a few trees)
// hold each part they share once. One holder's copy costs a count; Edit() gives a value of
// this holder's own, copied from the shared one if others hold it. An empty holder reads as
// T{} and allocates nothing until edited.
//
// Thread safety as std::shared_ptr's: holders of one value may be copied, read and dropped
// from several threads; one holder is edited from one thread at a time. A reference from
// Edit() is good until the holder is next copied (the copy shares what it refers to).
#pragma once

#include <atomic>
#include <cstdint>
#include <utility>

namespace leaflux {

template <class T>
class CopyOnWrite {
  public:
    CopyOnWrite() = default;
    CopyOnWrite(const CopyOnWrite& other) : block_(other.block_) {
        if (block_) block_->holders.fetch_add(1, std::memory_order_relaxed);
    }
    CopyOnWrite(CopyOnWrite&& other) noexcept : block_(std::exchange(other.block_, nullptr)) {}
    CopyOnWrite& operator=(const CopyOnWrite& other) {
        if (this != &other) *this = CopyOnWrite(other);
        return *this;
    }
    CopyOnWrite& operator=(CopyOnWrite&& other) noexcept {
        std::swap(block_, other.block_);
        return *this;
    }
    ~CopyOnWrite() { Release(); }

    const T& operator*() const { return block_ ? block_->value : Empty(); }
    const T* operator->() const { return &**this; }

    // The value to change: this holder's own.
    T& Edit() {
        if (!block_) {
            block_ = new Block;
        } else if (block_->holders.load(std::memory_order_acquire) > 1) {
            Block* own = new Block{block_->value, {1}};
            Release();
            block_ = own;
        }
        return block_->value;
    }

    // Whether both hold the same value object (copies of one another, neither edited since).
    bool SharesWith(const CopyOnWrite& other) const { return block_ == other.block_; }

  private:
    struct Block {
        [[no_unique_address]] T value{};  // the count may go in its tail padding
        std::atomic<std::uint32_t> holders{1};
    };
    static const T& Empty() {
        static const T empty{};
        return empty;
    }
    void Release() {
        if (block_ && block_->holders.fetch_sub(1, std::memory_order_acq_rel) == 1) delete block_;
        block_ = nullptr;
    }

    Block* block_ = nullptr;  // null: T{}
};

}  // namespace leaflux
