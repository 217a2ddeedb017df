// The one place GL and EGL headers enter the project. epoxy must come before
// EGL (khrplatform conflict otherwise, see shared/HEADLESS-GL.md).
#pragma once

#include <epoxy/gl.h>  // IWYU pragma: export
