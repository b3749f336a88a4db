// ascorr_text/c_format.hpp: printf-style formatting in the "C" locale, whatever
// locale the program runs in. printf's %f, %e and %g write the decimal point of
// the C library's current locale: a host program, or Python's
// locale.setlocale(LC_ALL, "de_DE.UTF-8"), turns 0.5 into "0,5", inside a CSV
// field and in every report. The command line never calls setlocale (a C
// program starts in "C"); the library is used by programs that do, so every
// printf-style call of the host side (host_sim/, hal/linux/, python/src/) goes
// through these, and a test (tests/CMakeLists.txt, numbers_locale_free) finds
// any other. Reading is std::from_chars (numbers.hpp), locale-free already.
//
// How: POSIX uselocale() sets the calling thread's locale to a "C" locale made
// once, for the call only; other threads and the process's locale are left as
// they are. Thread-safe; no allocation after the first call.
#pragma once

#include <locale.h>  // newlocale, uselocale, freelocale (POSIX 2008)

#include <cstdarg>
#include <cstddef>
#include <cstdio>

namespace ascorr::text {

// The "C" locale, made on first use and kept for the program's life.
inline locale_t c_locale() noexcept {
    static const locale_t c = newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(nullptr));
    return c;
}

// The calling thread in the "C" locale for this object's lifetime.
class CLocaleScope {
public:
    CLocaleScope() noexcept : previous_(c_locale() != nullptr ? uselocale(c_locale()) : nullptr) {}
    ~CLocaleScope() {
        if (previous_ != nullptr) {
            uselocale(previous_);
        }
    }
    CLocaleScope(const CLocaleScope&) = delete;
    CLocaleScope& operator=(const CLocaleScope&) = delete;

private:
    locale_t previous_;
};

// std::vsnprintf, std::snprintf and std::fprintf in the "C" locale.
__attribute__((format(printf, 3, 0))) inline int c_vsnprintf(char* buf, std::size_t size, const char* fmt,
                                                             std::va_list ap) noexcept {
    const CLocaleScope c;
    return std::vsnprintf(buf, size, fmt, ap);
}

__attribute__((format(printf, 3, 4))) inline int c_snprintf(char* buf, std::size_t size, const char* fmt,
                                                            ...) noexcept {
    std::va_list ap;
    va_start(ap, fmt);
    const int n = c_vsnprintf(buf, size, fmt, ap);
    va_end(ap);
    return n;
}

__attribute__((format(printf, 2, 3))) inline int c_fprintf(std::FILE* f, const char* fmt, ...) noexcept {
    const CLocaleScope c;
    std::va_list ap;
    va_start(ap, fmt);
    const int n = std::vfprintf(f, fmt, ap);
    va_end(ap);
    return n;
}

}  // namespace ascorr::text
