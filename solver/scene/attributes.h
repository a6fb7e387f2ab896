// A node's named numbers (OPF's attributes, a growth model's): a few a node, kept sorted by
// name in one block, held by pointer so that a node without any pays 8 bytes. A std::map
// cost 48 bytes a node and about 80 an entry, a std::vector in place 24. The nodes of placed
// structures share them with their whole body (NodeBody, copy on write), so that a copy of
// the attributes is a copy of their entries.
#pragma once

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace leaflux {

class Attributes {
  public:
    using value_type = std::pair<std::string, double>;
    using const_iterator = std::vector<value_type>::const_iterator;

    Attributes() = default;
    Attributes(const Attributes& other)
        : entries_(other.entries_ ? std::make_unique<Entries>(*other.entries_) : nullptr) {}
    Attributes(Attributes&&) noexcept = default;
    Attributes& operator=(const Attributes& other) {
        if (this != &other) *this = Attributes(other);
        return *this;
    }
    Attributes& operator=(Attributes&&) noexcept = default;
    ~Attributes() = default;

    // The value named so, made 0 if absent (as std::map's).
    double& operator[](std::string_view name) {
        Entries& entries = Made();
        const auto at = LowerBound(entries.begin(), entries.end(), name);
        if (at != entries.end() && at->first == name) return at->second;
        return entries.emplace(at, std::string(name), 0.0)->second;
    }
    const_iterator find(std::string_view name) const {
        const auto at = LowerBound(begin(), end(), name);
        return at != end() && at->first == name ? at : end();
    }
    std::size_t count(std::string_view name) const { return find(name) != end() ? 1 : 0; }
    double at(std::string_view name) const {
        const auto found = find(name);
        if (found == end()) throw std::out_of_range("no attribute " + std::string(name));
        return found->second;
    }
    // Pairs (first: name, second: value) in any order; a name already here keeps its value.
    template <class Iterator>
    void insert(Iterator first, Iterator last) {
        for (; first != last; ++first) {
            Entries& entries = Made();
            const auto at = LowerBound(entries.begin(), entries.end(), first->first);
            if (at == entries.end() || at->first != first->first)
                entries.emplace(at, first->first, first->second);
        }
    }

    const_iterator begin() const { return Held().begin(); }
    const_iterator end() const { return Held().end(); }
    std::size_t size() const { return Held().size(); }
    bool empty() const { return Held().empty(); }
    bool operator==(const Attributes& other) const { return Held() == other.Held(); }

  private:
    using Entries = std::vector<value_type>;
    const Entries& Held() const {
        static const Entries none;
        return entries_ ? *entries_ : none;
    }
    Entries& Made() {
        if (!entries_) entries_ = std::make_unique<Entries>();
        return *entries_;
    }
    // Where `name` is, or would go.
    template <class Iterator>
    static Iterator LowerBound(Iterator first, Iterator last, std::string_view name) {
        return std::lower_bound(
            first, last, name, [](const value_type& e, std::string_view n) { return e.first < n; });
    }

    std::unique_ptr<Entries> entries_;  // null: none
};

}  // namespace leaflux
