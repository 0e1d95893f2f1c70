// The Python module `tailor` (imported as tailor._tailor by the package's __init__.py).
#include "bindings.h"
#include "tailor/version.h"

PYBIND11_MODULE(_tailor, m) {
  namespace tp = tailor::python;
  m.doc() =
      "tailor: texture mapping of triangle meshes by homogeneous patch discovery, and self-tileable "
      "textures. load/Mesh -> map -> save; tile for textures; evaluate for any UV map.";
  m.attr("__version__") = TAILOR_VERSION_STRING;
  tp::bind_errors(m);
  tp::bind_mesh(m);
  tp::bind_map(m);
  tp::bind_tile(m);
  tp::bind_tile_set(m);
  tp::bind_eval(m);
  tp::bind_save(m);
  tp::bind_chunks(m);
  tp::bind_tiles(m);
}
