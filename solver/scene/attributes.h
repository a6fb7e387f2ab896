// A node's named numbers (OPF's attributes, a growth model's): a few a node, kept sorted by
// name in one block, held by pointer so that a node without any pays 8 bytes. A std::map
// cost 48 bytes a node and about 80 an entry, a std::vector in place 24. The block is shared
// by copies until one of them changes (copy on write): the nodes of placed structures
// (leaflux.v1.Scene.placements) share their structure's. Each of the paper's plantation's
// 1.9 M leaves held a block of its own, about 100 bytes: shared, the scene loaded went
// from 1,040 to 818 MiB.
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "solver/util/copy_on_write.h"

namespace leaflux {

class Attributes {
  public:
    using value_type = std::pair<std::string, double>;
    using const_iterator = std::vector<value_type>::const_iterator;

    Attributes() = default;

    // The value named so, made 0 if absent (as std::map's). The reference is good until the
    // attributes are next copied (the copy shares what it refers to).
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
    const Entries& Held() const { return *entries_; }
    // The entries to change: this node's own, copied from the shared ones.
    Entries& Made() { return entries_.Edit(); }
    // Where `name` is, or would go.
    template <class Iterator>
    static Iterator LowerBound(Iterator first, Iterator last, std::string_view name) {
        return std::lower_bound(
            first, last, name, [](const value_type& e, std::string_view n) { return e.first < n; });
    }

    CopyOnWrite<Entries> entries_;
};

}  // namespace leaflux
