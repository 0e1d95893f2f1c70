// The HTTP API of `tailor edit` over one EditSession (docs/edit-api.md): edits, undo and redo, the
// corner UVs of a version, the current .glb, saving, and the background settle after a pause.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "http_server.h"
#include "map_shared.h"
#include "tailor/edit_session.h"
#include "tailor/image.h"
#include "tailor/topology.h"

namespace tailor::cli {

//! What the API needs besides the session: inputs for the options that depend on them, how the .glb
//! is written, and where a save goes.
struct EditContext {
  std::unique_ptr<EditSession> session;
  Topology topology;        //!< of the session's mesh, for "axis": "auto"
  Image texture;            //!< the --texture image (empty without), for "field_following": "auto"
  MeshOutput output;        //!< how the .glb is written (the texture embedded, compression, up)
  std::string name;         //!< the mesh file's name, for the page's title
  std::string input;        //!< the mesh file as given, for the replay command
  std::string texture_arg;  //!< --texture as given ("" without), for the replay command
  std::string texture_url;  //!< where the page finds the texture ("" without)
  std::string glb_path;     //!< save targets: -o, and the seam faces and strokes beside it
  std::string seam_faces_path;
  std::string strokes_path;
  std::string scratch_dir;  //!< a private temporary folder for /api/model.glb
  bool quiet = false;
};

//! Settling waits this long after the last edit (the user paused).
inline constexpr std::chrono::milliseconds kSettlePause{300};

class EditApi {
 public:
  explicit EditApi(EditContext& context);

  //! Registers the API's handlers (GET /api/state, /api/mesh, /api/status, /api/uv, /api/model.glb;
  //! POST /api/edit, /api/undo, /api/redo, /api/save).
  void install(StaticServer& server);

  //! The settler: settles the session once no edit came for kSettlePause, until `stop` is set.
  //! Run on its own thread.
  void run_settler(const std::atomic<bool>& stop);

  //! Wakes the settler (to see `stop`).
  void wake();

 private:
  HttpResponse edit(const HttpRequest& request);
  HttpResponse undo_redo(bool redo);
  HttpResponse status() const;
  HttpResponse state() const;
  HttpResponse uv(const HttpRequest& request) const;
  HttpResponse model();
  HttpResponse save();
  void edited();  // an edit landed: the settler waits for the next pause
  // Settles (if needed) and takes a snapshot of a settled version; false when edits keep coming.
  bool settled_snapshot(Atlas& atlas, std::vector<uint8_t>& seam_faces, std::vector<OrientationStroke>& strokes,
                        MapTextureOptions& options, uint64_t& version);

  EditContext& context_;
  // Undo steps of the API: a brush stroke is sent as several edits ("join": true after the first)
  // and undone as one. Each entry counts the session's own steps it spans.
  std::mutex edit_mutex_;  // edits, undo and redo one at a time, with the step counts
  std::vector<uint32_t> undo_steps_;
  std::vector<uint32_t> redo_steps_;
  bool step_open_ = false;  // the last edit may be joined
  std::string mesh_bytes_;  // GET /api/mesh, built once
  std::mutex settle_mutex_;
  std::condition_variable settle_wake_;
  std::chrono::steady_clock::time_point last_edit_{};
  bool settle_pending_ = false;
  // /api/uv: the UVs of the version served last; the page's next fetch asks for the faces changed
  // since it, which then costs one copy out of the session instead of two.
  mutable std::mutex uv_mutex_;
  mutable uint64_t uv_version_ = UINT64_MAX;
  mutable std::vector<float> uv_last_;
  std::mutex model_mutex_;  // /api/model.glb: one export at a time, the last one cached
  uint64_t model_version_ = UINT64_MAX;
  std::string model_bytes_;
};

//! The `tailor map` command line that gives the same .glb as a save with these options.
std::string replay_command(const EditContext& context, const MapTextureOptions& options);

}  // namespace tailor::cli
