// The channels of a radiosity solve and the tables that hold a value per channel for each
// node. A channel is one band of one beam: a scene's solve has a channel per band; a phase
// function's solve (Soler 2003 §4.2) lights one structure under many unit beams at once,
// for the links do not depend on where the light comes from, and has bands × beams
// channels, chosen at run time. Channel c is band c % bands of beam c / bands.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

namespace leaflux {

inline constexpr int kUpper = 0, kLower = 1;  // the sides of a patch (upper: along its normal)

// How refinement weighs light of several channels into the one number it compares with ε:
// the sum of every channel (a scene's bands share one threshold), or the brightest beam
// (a phase function must be as accurate under every beam, each beam a scene of its own).
enum class ChannelMeasure { kSum, kWorstBeam };

struct Channels {
    int bands = 1;
    int beams = 1;
    ChannelMeasure measure = ChannelMeasure::kSum;

    int Count() const { return bands * beams; }
    int BandOf(int channel) const { return channel % bands; }

    // The light refinement judges by, from a value per channel.
    double Measure(const double* values) const {
        if (measure == ChannelMeasure::kSum || beams == 1) {
            double total = 0.0;
            for (int c = 0; c < Count(); ++c) total += values[c];
            return total;
        }
        double worst = 0.0;
        for (int beam = 0; beam < beams; ++beam) {
            double total = 0.0;
            for (int b = 0; b < bands; ++b) total += values[beam * bands + b];
            worst = std::max(worst, total);
        }
        return worst;
    }
};

// Room for one value per channel, on the stack for a few channels and on the heap beyond:
// scratch for the hot loops, which must not allocate per link.
class ChannelScratch {
  public:
    explicit ChannelScratch(int count)
        : heap_(count > kInline ? new double[count] : nullptr),
          data_(count > kInline ? heap_.get() : inline_) {}
    ChannelScratch(const ChannelScratch&) = delete;
    ChannelScratch& operator=(const ChannelScratch&) = delete;
    double* Data() { return data_; }

  private:
    static constexpr int kInline = 16;
    double inline_[kInline];
    std::unique_ptr<double[]> heap_;
    double* data_;
};

// Rows of `width` values, zero when made: one row per node (or per cluster slot). Rows
// move when the table grows: hold no pointer into it across a Resize.
template <class T>
class Table {
  public:
    Table() = default;
    explicit Table(std::size_t width, std::size_t rows = 0) : width_(width), data_(width * rows) {}

    T* operator[](std::size_t row) { return data_.data() + row * width_; }
    const T* operator[](std::size_t row) const { return data_.data() + row * width_; }
    std::size_t Width() const { return width_; }
    std::size_t Rows() const { return width_ > 0 ? data_.size() / width_ : 0; }

    void Resize(std::size_t rows) { data_.resize(rows * width_, T{}); }
    void Assign(std::size_t rows) { data_.assign(rows * width_, T{}); }
    void ClearRow(std::size_t row) { std::fill_n((*this)[row], width_, T{}); }
    void CopyRow(std::size_t to, std::size_t from) {
        std::copy_n((*this)[from], width_, (*this)[to]);
    }

  private:
    std::size_t width_ = 0;
    std::vector<T> data_;
};

// A value per side and channel for each node: a row is the upper side's channels, then the
// lower side's.
class SideTable {
  public:
    SideTable() = default;
    explicit SideTable(int channels, std::size_t rows = 0)
        : channels_(channels), table_(2 * static_cast<std::size_t>(channels), rows) {}

    double* operator()(std::size_t node, int side) { return table_[node] + side * channels_; }
    const double* operator()(std::size_t node, int side) const {
        return table_[node] + side * channels_;
    }
    int Channels() const { return channels_; }
    std::size_t Rows() const { return table_.Rows(); }

    void Resize(std::size_t rows) { table_.Resize(rows); }
    void Assign(std::size_t rows) { table_.Assign(rows); }
    void ClearRow(std::size_t node) { table_.ClearRow(node); }
    void CopyRow(std::size_t to, std::size_t from) { table_.CopyRow(to, from); }

  private:
    int channels_ = 0;
    Table<double> table_;
};

}  // namespace leaflux
