// The OSMesa and OpenGL entry points the preview renderer calls, loaded from libOSMesa with dlopen
// on the first picture instead of linked.
//
// Why: libOSMesa pulls in Mesa's llvmpipe and with it libLLVM, libz3 and the ICU data; loading them
// costs every process ~52 MB resident before main (measured on Debian 12: an empty program linked
// with -lOSMesa peaks at 53 MB, without it at 1 MB). Only `tailor map --preview` and `tailor
// render` draw, so only they pay it; `tailor map` on a 1.5 M-face mesh peaked a quarter higher
// with the library linked.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <string>

namespace tailor::internal {

// X(name) for every function osmesa_backend.cpp calls (a call to one not listed fails to link:
// libOSMesa is not on the link line).
#define TAILOR_GL_ENTRY_POINTS(X) \
  X(OSMesaCreateContextExt)       \
  X(OSMesaDestroyContext)         \
  X(OSMesaGetCurrentContext)      \
  X(OSMesaMakeCurrent)            \
  X(glActiveTexture)              \
  X(glAttachShader)               \
  X(glBindAttribLocation)         \
  X(glBindBuffer)                 \
  X(glBindTexture)                \
  X(glBufferData)                 \
  X(glClear)                      \
  X(glClearColor)                 \
  X(glColor3ub)                   \
  X(glColor4ub)                   \
  X(glColorMaterial)              \
  X(glColorPointer)               \
  X(glCompileShader)              \
  X(glCreateProgram)              \
  X(glCreateShader)               \
  X(glDeleteBuffers)              \
  X(glDeleteProgram)              \
  X(glDeleteShader)               \
  X(glDeleteTextures)             \
  X(glDepthFunc)                  \
  X(glDisable)                    \
  X(glDisableClientState)         \
  X(glDisableVertexAttribArray)   \
  X(glDrawArrays)                 \
  X(glDrawElements)               \
  X(glEnable)                     \
  X(glEnableClientState)          \
  X(glEnableVertexAttribArray)    \
  X(glFinish)                     \
  X(glGenBuffers)                 \
  X(glGenTextures)                \
  X(glGetError)                   \
  X(glGetIntegerv)                \
  X(glGetProgramiv)               \
  X(glGetShaderInfoLog)           \
  X(glGetShaderiv)                \
  X(glGetUniformLocation)         \
  X(glLightModelfv)               \
  X(glLightModeli)                \
  X(glLightfv)                    \
  X(glLineWidth)                  \
  X(glLinkProgram)                \
  X(glLoadIdentity)               \
  X(glLoadMatrixf)                \
  X(glMatrixMode)                 \
  X(glMultMatrixf)                \
  X(glNormalPointer)              \
  X(glPixelStorei)                \
  X(glPolygonOffset)              \
  X(glScalef)                     \
  X(glShadeModel)                 \
  X(glShaderSource)               \
  X(glTexCoordPointer)            \
  X(glTexEnvi)                    \
  X(glTexImage2D)                 \
  X(glTexParameteri)              \
  X(glUniform1i)                  \
  X(glUniform3f)                  \
  X(glUseProgram)                 \
  X(glVertexAttrib4f)             \
  X(glVertexAttribPointer)        \
  X(glVertexPointer)              \
  X(glViewport)

// One pointer per entry point, named as the function (decltype of the header's declaration).
struct GlApi {
#define TAILOR_GL_POINTER(name) decltype(&::name) name = nullptr;
  TAILOR_GL_ENTRY_POINTS(TAILOR_GL_POINTER)
#undef TAILOR_GL_POINTER
};

// Loads libOSMesa and every entry point, once per process (thread-safe). Returns false with
// `error` set (what is missing, and the package that has it) when it cannot; nothing is loaded
// then, and gl() must not be called.
bool load_gl_api(std::string& error);

// The entry points; load_gl_api must have returned true.
const GlApi& gl();

}  // namespace tailor::internal
