// tailor: the library's version. The one place it is written: CMakeLists.txt reads it from here.
#pragma once

#define TAILOR_VERSION_MAJOR 0
#define TAILOR_VERSION_MINOR 1
#define TAILOR_VERSION_PATCH 0
//! One number that grows with every release: major * 10000 + minor * 100 + patch.
#define TAILOR_VERSION (TAILOR_VERSION_MAJOR * 10000 + TAILOR_VERSION_MINOR * 100 + TAILOR_VERSION_PATCH)
#define TAILOR_VERSION_STRING "0.1.0"
