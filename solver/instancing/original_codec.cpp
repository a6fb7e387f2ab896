#include "solver/instancing/original_codec.h"

#include <bit>
#include <cstring>
#include <stdexcept>

#include "solver/util/error.h"

namespace leaflux {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the blob layout is the little-endian host's");

constexpr char kMagic[4] = {'L', 'F', 'O', 'R'};
// No function of a known resolution has more values (514² directions × 64 bands).
constexpr std::uint32_t kMaxValues = 514u * 514u * 64u;

class Writer {
  public:
    explicit Writer(std::size_t expectedBytes) { bytes_.reserve(expectedBytes); }
    template <class T>
    void Put(const T& value) {
        PutBytes(&value, sizeof value);
    }
    void PutString(const std::string& text) {
        Put(static_cast<std::uint32_t>(text.size()));
        PutBytes(text.data(), text.size());
    }
    void PutFloats(std::span<const float> values) {
        Put(static_cast<std::uint32_t>(values.size()));
        PutBytes(values.data(), values.size_bytes());
    }
    std::vector<std::uint8_t> Take() { return std::move(bytes_); }

  private:
    void PutBytes(const void* data, std::size_t size) {
        const std::size_t at = bytes_.size();
        bytes_.resize(at + size);
        if (size) std::memcpy(bytes_.data() + at, data, size);
    }

    std::vector<std::uint8_t> bytes_;
};

class Reader {
  public:
    Reader(std::span<const std::uint8_t> bytes, const std::string& what)
        : bytes_(bytes), what_(what) {}
    template <class T>
    T Get(const char* field) {
        T value;
        Take(&value, sizeof value, field);
        return value;
    }
    std::string GetString(const char* field) {
        const auto size = Get<std::uint32_t>(field);
        if (size > Remaining()) Fail(field, "a string longer than the blob");
        std::string text(size, '\0');
        Take(text.data(), size, field);
        return text;
    }
    std::vector<float> GetFloats(const char* field) {
        const auto count = Get<std::uint32_t>(field);
        if (count > kMaxValues || count * sizeof(float) > Remaining())
            Fail(field, std::to_string(count) + " values do not fit the blob");
        std::vector<float> values(count);
        Take(values.data(), count * sizeof(float), field);
        return values;
    }
    std::size_t Remaining() const { return bytes_.size() - at_; }
    [[noreturn]] void Fail(const char* field, const std::string& message) const {
        throw InputError(ErrorCode::kParse, what_ + "." + field,
                         message + " (at byte " + std::to_string(at_) + " of " +
                             std::to_string(bytes_.size()) + ")");
    }

  private:
    void Take(void* out, std::size_t size, const char* field) {
        if (size > Remaining()) Fail(field, "the blob ends early");
        std::memcpy(out, bytes_.data() + at_, size);
        at_ += size;
    }

    std::span<const std::uint8_t> bytes_;
    const std::string& what_;
    std::size_t at_ = 0;
};

}  // namespace

std::vector<std::uint8_t> EncodeOriginal(const Original& original) {
    Writer out(OriginalBytes(original));
    for (const char c : kMagic) out.Put(c);
    out.Put(kOriginalFormatVersion);
    for (int axis = 0; axis < 3; ++axis) out.Put(original.boxMin[axis]);
    for (int axis = 0; axis < 3; ++axis) out.Put(original.boxMax[axis]);
    const SphereFunction& tau = original.transmittance;
    out.Put(static_cast<std::int32_t>(tau.Level()));
    out.Put(static_cast<std::int32_t>(tau.Channels()));
    out.PutFloats(tau.Values());
    const PhaseFunction& phase = original.phase;
    out.Put(static_cast<std::uint8_t>(phase.Kind()));
    out.Put(static_cast<std::int32_t>(phase.Level()));
    out.Put(static_cast<std::int32_t>(phase.Bands()));
    out.PutFloats(phase.Values());
    const SphereFunction& absorption = original.absorption;
    out.Put(static_cast<std::int32_t>(absorption.Level()));
    out.Put(static_cast<std::int32_t>(absorption.Channels()));
    out.PutFloats(absorption.Values());
    const OriginalProvenance& p = original.provenance;
    out.PutString(p.representative);
    out.Put(p.leafCount);
    out.Put(p.leafAreaM2);
    out.PutString(p.method);
    out.Put(p.accuracy);
    out.Put(p.computeSeconds);
    out.Put(p.transmittanceRelativeError);
    out.Put(p.phaseRelativeError);
    return out.Take();
}

Original DecodeOriginal(std::span<const std::uint8_t> blob, const std::string& what) {
    Reader in(blob, what);
    for (const char c : kMagic) {
        if (in.Get<char>("magic") != c) in.Fail("magic", "not an original (no \"LFOR\")");
    }
    // Format 1 had no absorption: read still, the absorption empty.
    const auto version = in.Get<std::uint8_t>("format");
    if (version != 1 && version != kOriginalFormatVersion)
        in.Fail("format", "format version " + std::to_string(version) +
                              ", this leaflux reads 1 to " +
                              std::to_string(kOriginalFormatVersion));
    Original original;
    for (int axis = 0; axis < 3; ++axis) original.boxMin[axis] = in.Get<double>("box_min");
    for (int axis = 0; axis < 3; ++axis) original.boxMax[axis] = in.Get<double>("box_max");
    try {
        const auto tauLevel = in.Get<std::int32_t>("transmittance.level");
        const auto tauChannels = in.Get<std::int32_t>("transmittance.channels");
        std::vector<float> tau = in.GetFloats("transmittance.values");
        // A structure whose τ was not computed has none: keep it empty, not zero-filled.
        if (!(tau.empty() && tauChannels == 0))
            original.transmittance =
                SphereFunction::FromValues(tauLevel, tauChannels, std::move(tau));
        const auto kind = in.Get<std::uint8_t>("phase.kind");
        if (kind > static_cast<std::uint8_t>(PhaseKind::kBiDirectional))
            in.Fail("phase.kind", "unknown phase kind " + std::to_string(kind));
        const auto level = in.Get<std::int32_t>("phase.level");
        const auto bands = in.Get<std::int32_t>("phase.bands");
        std::vector<float> values = in.GetFloats("phase.values");
        if (!(values.empty() && bands == 0))
            original.phase = PhaseFunction::FromValues(static_cast<PhaseKind>(kind), level, bands,
                                                       std::move(values));
        if (version >= 2) {
            const auto absorptionLevel = in.Get<std::int32_t>("absorption.level");
            const auto absorptionChannels = in.Get<std::int32_t>("absorption.channels");
            std::vector<float> absorption = in.GetFloats("absorption.values");
            if (!(absorption.empty() && absorptionChannels == 0)) {
                // Read per band of f: one value a band, or a lookup past its end.
                if (absorptionChannels != original.phase.Bands())
                    in.Fail("absorption.channels",
                            std::to_string(absorptionChannels) + " channels for " +
                                std::to_string(original.phase.Bands()) + " bands of f");
                original.absorption = SphereFunction::FromValues(
                    absorptionLevel, absorptionChannels, std::move(absorption));
            }
        }
    } catch (const std::invalid_argument& e) {
        in.Fail("functions", e.what());
    }
    OriginalProvenance& p = original.provenance;
    p.representative = in.GetString("representative");
    p.leafCount = in.Get<std::int64_t>("leaf_count");
    p.leafAreaM2 = in.Get<double>("leaf_area_m2");
    p.method = in.GetString("method");
    p.accuracy = in.Get<double>("accuracy");
    p.computeSeconds = in.Get<double>("compute_seconds");
    p.transmittanceRelativeError = in.Get<double>("transmittance_relative_error");
    p.phaseRelativeError = in.Get<double>("phase_relative_error");
    if (in.Remaining() != 0)
        in.Fail("end", std::to_string(in.Remaining()) + " bytes after the original");
    return original;
}

std::size_t OriginalBytes(const Original& original) {
    return sizeof(Original) + original.transmittance.Values().size_bytes() +
           original.phase.Bytes() + original.absorption.Values().size_bytes() +
           original.provenance.representative.capacity() + original.provenance.method.capacity();
}

}  // namespace leaflux
