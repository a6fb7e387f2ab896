// A node's named numbers (OPF's attributes, a growth model's): a few a node, kept sorted by
// name in one block. A std::map cost 48 bytes a node and about 80 an entry, a tenth of a
// plantation's scene.
#pragma once

#include <algorithm>
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

    // The value named so, made 0 if absent (as std::map's).
    double& operator[](std::string_view name) {
        const auto at = LowerBound(name);
        if (at != entries_.end() && at->first == name) return at->second;
        return entries_.emplace(at, std::string(name), 0.0)->second;
    }
    const_iterator find(std::string_view name) const {
        const auto at = LowerBound(name);
        return at != entries_.end() && at->first == name ? const_iterator(at) : end();
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
            const auto at = LowerBound(first->first);
            if (at == entries_.end() || at->first != first->first)
                entries_.emplace(at, first->first, first->second);
        }
    }

    const_iterator begin() const { return entries_.begin(); }
    const_iterator end() const { return entries_.end(); }
    std::size_t size() const { return entries_.size(); }
    bool empty() const { return entries_.empty(); }
    bool operator==(const Attributes&) const = default;

  private:
    using Entries = std::vector<value_type>;
    // Where `name` is, or would go.
    template <class Iterator>
    static Iterator LowerBound(Iterator first, Iterator last, std::string_view name) {
        return std::lower_bound(
            first, last, name, [](const value_type& e, std::string_view n) { return e.first < n; });
    }
    Entries::iterator LowerBound(std::string_view name) {
        return LowerBound(entries_.begin(), entries_.end(), name);
    }
    const_iterator LowerBound(std::string_view name) const {
        return LowerBound(entries_.begin(), entries_.end(), name);
    }

    Entries entries_;
};

}  // namespace leaflux
