#pragma once
// Private to zcheck_check (check/src/): the table of slopes a PixelJudge made for whole images
// (SlopeSource::TableOfSeen) keeps, and how the comparison's kernels read it.
//
// The first time any triangle of a block of 64 consecutive ones is asked for, the whole block's
// m is computed (several per instruction, its corners read as a stream) into a table of 8 bytes
// per triangle, where every later question finds it with one load. Only the blocks of triangles
// the judge is asked about are computed: the million-triangle speed workload shows 246,522 of
// its triangles at 1080p, in 4,237 of its 15,665 blocks, and a table of all of them computed up
// front cost 3-4.5 ms on two threads (9.5 on one) against a comparison of 11-18 ms. (Slopes
// remembered per thread instead, triangle by triangle, cost the comparison more: ~922,000 runs
// of pixels to look up per frame, with their corners gathered at random.)
//
// Thread-safe: block b's state byte goes 0 (not computed) → 1 (being computed, by the thread
// that made it so) → kReady (its slopes in the table, stored with release: read them after an
// acquire). Each entry is written once, by const calls, under its block's state.
#include "zcheck/compare.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/detail/lane_mask.h"
#include "zcheck/large_buffer.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>

namespace zcheck {

class SlopeTable {
public:
    // Triangles [b·kBlock, (b+1)·kBlock) are block b.
    static constexpr std::uint32_t kBlock = 64;

    // The slopes of `scene`'s triangles through `frame` (both must outlive the table); blocks are
    // computed in form `form` (kernel_form.h; each bit-identical to the baseline's).
    SlopeTable(const Scene& scene, const DepthSlopeFrame& frame, KernelForm form);

    std::uint32_t blockCount() const { return blockCount_; }
    // The table's entry for any primitive not of the scene: 0, and always there.
    std::uint32_t none() const { return none_; }
    // Whether primitive p's slope (p < none()) is in the table, its block computed now by this
    // thread if need be; false while another thread computes it.
    bool ready(std::uint32_t p) const
    {
        return blockState(p / kBlock).load(std::memory_order_acquire) == kReady || makeBlockReady(p / kBlock);
    }
    double at(std::uint32_t p) const { return slopeOfTriangle_[p]; }

    // The table when it holds the slopes of every primitive[0, n) (every block asked about
    // ready, or made ready now by this thread), else null (another thread is computing one of
    // them): slope(p) is then table[min(p, none())], for a kernel that looks them up itself.
    ZCHECK_ALWAYS_INLINE const double* tableFor(const std::uint32_t* primitive, std::size_t n) const
    {
        // Each block asked about once per run of lanes in it (a row of a frame crosses few),
        // found 64 lanes at a time without a branch per lane; none for a primitive not of the scene.
        const std::uint32_t blocks = blockCount_;
        for (std::size_t j0 = 0; j0 < n; j0 += kBlock) {
            const std::uint32_t* p = primitive + j0;
            const std::size_t lanes = std::min<std::size_t>(kBlock, n - j0);
            alignas(64) std::uint8_t runStart[kBlock];
            runStart[0] = p[0] / kBlock < blocks && (j0 == 0 || p[0] / kBlock != p[-1] / kBlock);
            for (std::size_t j = 1; j < lanes; ++j)
                runStart[j] = (p[j] / kBlock < blocks) & (p[j] / kBlock != p[j - 1] / kBlock);
            if (!blocksMadeReady(p, laneBits(runStart, lanes))) return nullptr;
        }
        std::atomic_thread_fence(std::memory_order_acquire);  // blocksMadeReady's relaxed loads saw each block's release
        return slopeOfTriangle_.data();
    }
    // tableFor of up to 64 lanes whose run starts the caller found itself: the lanes j of
    // `runStarts` (bits) whose primitive[j] lies in a block of the scene (< blockCount() after
    // division by kBlock) and in another block than primitive[j − 1], and lane 0 when it does.
    // (The comparison's AVX-512 form finds them while it makes the row's surface.)
    ZCHECK_ALWAYS_INLINE const double* tableForRuns(const std::uint32_t* primitive, std::uint64_t runStarts) const
    {
        if (!blocksMadeReady(primitive, runStarts)) return nullptr;
        std::atomic_thread_fence(std::memory_order_acquire);  // as in tableFor
        return slopeOfTriangle_.data();
    }

private:
    static constexpr std::uint8_t kReady = 2;
    std::atomic<std::uint8_t>& blockState(std::uint32_t block) const { return blockState_[block]; }
    // Computes block b into the table unless another thread is computing it; whether it is ready.
    bool makeBlockReady(std::uint32_t block) const;
    // Whether the blocks of primitive[j] for the set bits j of `runStarts` are all ready, those
    // not ready yet computed now (makeBlockReady) unless another thread is at it (relaxed loads:
    // the caller fences before it reads the table). (Left to the lane-by-lane path, a row that
    // met a new block looked up each of its lanes' slopes alone: 12 % of 1080p's tile rows.)
    ZCHECK_ALWAYS_INLINE bool blocksMadeReady(const std::uint32_t* primitive, std::uint64_t runStarts) const
    {
        bool ready = true;
        forEachSetBit(runStarts, [&](std::size_t j) ZCHECK_ALWAYS_INLINE {
            const std::uint32_t block = primitive[j] / kBlock;
            if (blockState(block).load(std::memory_order_relaxed) != kReady) ready &= makeBlockReady(block);
        });
        return ready;
    }

    const Scene& scene_;
    const DepthSlopeFrame& frame_;
    KernelForm form_;
    std::uint32_t none_ = 0, blockCount_ = 0;
    // m of triangle t once its block is ready; one entry more, 0, for any primitive not of the scene.
    mutable LargeVector<double> slopeOfTriangle_;
    std::unique_ptr<std::atomic<std::uint8_t>[]> blockState_;  // zeroed: no block computed
};

// judge.slope() of n primitives into `slope`: from the judge's table when it holds them all,
// else one at a time. Inlined, so that a lane loop of each form of a kernel (kernel_choice.h)
// loads several per instruction from the table once it finds every block asked about ready
// (most rows of a frame after its first few).
ZCHECK_ALWAYS_INLINE inline void slopesOf(const PixelJudge& judge, const std::uint32_t* primitive, std::size_t n,
                                          double* slope)
{
    if (const SlopeTable* table = judge.slopeTable())
        if (const double* entries = table->tableFor(primitive, n)) {
            const std::uint32_t none = table->none();
            for (std::size_t j = 0; j < n; ++j) slope[j] = entries[std::min(primitive[j], none)];
            return;
        }
    for (std::size_t j = 0; j < n; ++j) slope[j] = judge.slope(primitive[j]);
}

}  // namespace zcheck
