// tailor: the whole public API in one include. Link what the headers you use belong to:
//   tailor::core     mesh.h io.h gltf.h image.h topology.h orientation.h mapping.h axis_choice.h
//                    atlas.h metrics.h stability.h export.h status.h version.h
//                    texture_direction.h edit_session.h
//   tailor::texture  image_ops.h tiling.h (tileable textures, OpenCV inside)
//   tailor::render   render.h (preview pictures, OSMesa inside)
// Including a header whose library is not linked is harmless as long as none of its functions is
// called. Every function and type lives in namespace tailor; TAILOR_API (api.h) marks the exported
// declarations, the version macros (TAILOR_VERSION_STRING...) come from version.h.
#pragma once

#include "tailor/api.h"
#include "tailor/atlas.h"
#include "tailor/axis_choice.h"
#include "tailor/chunked_mapper.h"
#include "tailor/chunks.h"
#include "tailor/edit_session.h"
#include "tailor/export.h"
#include "tailor/gltf.h"
#include "tailor/image.h"
#include "tailor/image_ops.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/material.h"
#include "tailor/mesh.h"
#include "tailor/metrics.h"
#include "tailor/option_doc.h"
#include "tailor/orientation.h"
#include "tailor/progress.h"
#include "tailor/render.h"
#include "tailor/report.h"
#include "tailor/stability.h"
#include "tailor/status.h"
#include "tailor/texture_direction.h"
#include "tailor/tiling.h"
#include "tailor/topology.h"
#include "tailor/version.h"
