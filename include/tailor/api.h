// tailor: TAILOR_API marks the declarations of the public API. The libraries are compiled with
// hidden symbols (-fvisibility=hidden), so only what carries this mark is exported from a shared
// libtailor_*.so; everything else stays internal and cannot clash with a program's own symbols.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define TAILOR_API __attribute__((visibility("default")))
#else
#define TAILOR_API
#endif
