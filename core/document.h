#pragma once
/// \file document.h
/// The session document: everything a person made (strokes, lobes, edits as operations,
/// settings, seed, trees with their transforms). Versioned JSON, saved atomically.
/// Format: docs/session-format.md.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/edits.h"
#include "core/grower_choice.h"
#include "core/mesh.h"
#include "core/settings.h"
#include "core/stroke.h"

namespace lobe {

inline constexpr int kDocumentVersion = 1;

/// A lobe made from an imported mesh (OBJ, PLY, OFF) instead of strokes: the mesh as the
/// import made it (repaired, scaled, remeshed), in the lobe's own frame. Kept in the session
/// itself, so the session does not depend on the file it came from.
struct LobeModel {
    std::string source; ///< the file it was imported from (informational)
    TriangleMesh mesh;  ///< closed, outward; no feature edges
};

struct LobeRecord {
    std::int64_t id = 0;
    std::vector<std::int64_t> stroke_ids;
    std::string mesh_file; ///< relative to the document, empty until meshed
    /// Per-lobe settings that override the tree's (absent/empty: the tree's).
    std::optional<double> split_angle_deg;
    std::string species;
    std::optional<double> leaf_length_m;     ///< the leaf width keeps the tree's width/length ratio
    std::optional<int> leaves_per_node;
    std::optional<std::uint64_t> seed;       ///< keys the lobe's growth and leaf streams
    /// Set for a lobe imported from a mesh (then stroke_ids is empty). Shared and immutable,
    /// so copies of the document (undo snapshots) do not copy the mesh.
    std::shared_ptr<const LobeModel> model;

    /// A lobe of strokes with the tree's settings.
    static LobeRecord of_strokes(std::int64_t id, std::vector<std::int64_t> strokes = {}, std::string mesh_file = {})
    {
        LobeRecord r;
        r.id = id;
        r.stroke_ids = std::move(strokes);
        r.mesh_file = std::move(mesh_file);
        return r;
    }
};

/// Most vertices and triangles of an imported lobe mesh a session may hold.
inline constexpr std::size_t kMaxLobeModelVertices = 500000;
inline constexpr std::size_t kMaxLobeModelTriangles = 1000000;

/// Checks what a session may hold as a lobe's mesh: at most kMaxLobeModelVertices and
/// kMaxLobeModelTriangles, at least 4 triangles, every coordinate finite and within 1 km,
/// every index in range and no triangle repeating a vertex.
/// \throw InvalidInput (one line, starting with `where`) naming the first problem.
void validate_lobe_model(const LobeModel& model, const std::string& where);

/// One tree of the scene: variants and forests are several of these.
struct TreeInstance {
    std::int64_t id = 0;
    glm::mat4 transform{1.0f};
    std::uint64_t seed = 1;
    std::vector<std::int64_t> lobe_ids; ///< empty = all lobes
    GrowerChoice grower;                ///< the growth model and its parameters
};


struct Document {
    int version = kDocumentVersion;
    std::string source_recording; ///< the recording this session was replayed from, if any
    /// How much of source_recording the document holds: the actions derived from its first
    /// recording_frames hand frames (and the events up to the last of them) are applied.
    /// Written by live sessions at every save and autosave; absent when the document is not
    /// a position in a recording. `lobesketch recover` replays the rest (docs/crash-safety.md).
    std::optional<std::uint64_t> recording_frames;
    /// Set with recording_frames when the recording had ended when the document was saved:
    /// the actions of its end (events after the last frame, strokes still being drawn) are
    /// applied too, so nothing of that recording is left to replay.
    bool recording_finished = false;
    std::uint64_t seed = 1;
    Settings settings;
    std::vector<Stroke> strokes;
    std::vector<LobeRecord> lobes;
    std::vector<EditOperation> edits;
    std::vector<TreeInstance> trees;
};

/// The grower of the scene's tree: the first tree's, else the default (kDefaultGrowerName).
/// Today the scene holds one tree grown from every lobe; forests will grow one per entry.
const GrowerChoice& scene_grower(const Document& doc);

nlohmann::json document_to_json(const Document& doc);
/// \throw InvalidInput naming the offending field when the JSON is not a valid document.
Document document_from_json(const nlohmann::json& j);

/// Saves atomically (temporary file, flush, rename): the old file survives any crash.
/// \throw FileError
void save_document(const std::string& path, const Document& doc);
/// \throw FileError with a one-line reason naming the file.
Document load_document(const std::string& path);

/// The previous generation of an autosave: "PATH.1".
std::string previous_autosave_path(const std::string& path);
/// Saves an autosave as save_document does, first keeping the file it replaces as
/// previous_autosave_path(path) (a hard link, renamed into place: that file too is always a
/// whole document). Keeping the previous generation is best effort; the save itself throws.
/// \throw FileError
void save_autosave(const std::string& path, const Document& doc);

/// Most frames recording_frames may say (far above any recording's frame limit).
inline constexpr std::uint64_t kMaxDocumentRecordingFrames = 1u << 31;

/// Largest session file the loader accepts.
inline constexpr std::size_t kMaxDocumentBytes = 256u << 20;

/// Most of each list a session document may hold (docs/limits.md): the reader refuses a
/// document beyond them, naming the list, and the session builder refuses to add past them.
/// Each stroke holds at most kMaxStrokePoints points (core/stroke.h).
inline constexpr std::size_t kMaxDocumentStrokes = 100000;
inline constexpr std::size_t kMaxDocumentLobes = 1000;   ///< each is rebuilt and remeshed on load
inline constexpr std::size_t kMaxDocumentEdits = 20000;  ///< each pinch edit is a Laplacian solve on replay
inline constexpr std::size_t kMaxDocumentTrees = 1000;

} // namespace lobe
