// Internal invariants. A failed check is a bug in leaflux, never bad user input (that is
// an InputError, see error.h). Checks throw InternalError instead of aborting so that a
// daemon answers the request that hit the bug with an error and keeps serving.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace leaflux {

class InternalError : public std::logic_error {
  public:
    using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] inline void CheckFailed(const char* file, int line, const std::string& what) {
    std::ostringstream message;
    message << file << ":" << line << ": internal check failed: " << what;
    throw InternalError(message.str());
}

template <typename A, typename B>
[[noreturn]] void CheckOpFailed(const char* file, int line, const char* expression, const A& a,
                                const B& b) {
    std::ostringstream what;
    what << expression << " with " << a << " vs " << b;
    CheckFailed(file, line, what.str());
}
}  // namespace detail

}  // namespace leaflux

#define LEAFLUX_CHECK(condition)                                            \
    do {                                                                    \
        if (!(condition)) {                                                 \
            ::leaflux::detail::CheckFailed(__FILE__, __LINE__, #condition); \
        }                                                                   \
    } while (false)

#define LEAFLUX_CHECK_OP(a, op, b)                                                                 \
    do {                                                                                           \
        const auto& leafluxCheckA = (a);                                                           \
        const auto& leafluxCheckB = (b);                                                           \
        if (!(leafluxCheckA op leafluxCheckB)) {                                                   \
            ::leaflux::detail::CheckOpFailed(__FILE__, __LINE__, #a " " #op " " #b, leafluxCheckA, \
                                             leafluxCheckB);                                       \
        }                                                                                          \
    } while (false)

#define LEAFLUX_CHECK_EQ(a, b) LEAFLUX_CHECK_OP(a, ==, b)
#define LEAFLUX_CHECK_LT(a, b) LEAFLUX_CHECK_OP(a, <, b)
#define LEAFLUX_CHECK_LE(a, b) LEAFLUX_CHECK_OP(a, <=, b)

#ifdef NDEBUG
#define LEAFLUX_DCHECK(condition) \
    do {                          \
    } while (false)
#else
#define LEAFLUX_DCHECK(condition) LEAFLUX_CHECK(condition)
#endif
