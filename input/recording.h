#pragma once
/// \file recording.h
/// Recordings: the raw input of a session (hand joints, head pose, desktop mouse and
/// keyboard), in a compact binary form for real sessions and a line-per-frame text form for
/// hand-written fixtures. Everything derived (gestures, strokes, mode switches, edits) is
/// recomputed on replay; derived actions may be stored as annotations that replay checks
/// against and never applies. Format, version rules and limits: docs/recording-format.md.
/// Positions are metres in stage space, times seconds.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/hand_frame.h"

namespace lobe {

inline constexpr int kRecordingVersion = 1;

/// Limits that keep a hostile or broken file from exhausting memory (documented in
/// docs/recording-format.md). 648,000 frames is two hours at 90 Hz.
inline constexpr std::size_t kMaxRecordingFrames = 648000;
inline constexpr std::size_t kMaxRecordingEvents = 1000000;
inline constexpr std::size_t kMaxRecordingAnnotations = 1000000;

struct RecordingHeader {
    int version = kRecordingVersion;
    std::string source = "unknown";   ///< runtime or program that produced it ("openxr:Monado", "synth", "import-leap")
    std::string device = "unknown";   ///< tracker ("Leap Motion", "Meta Quest 3", "synthetic hand")
    std::string units = "m";          ///< always metres after import
    std::string space = "stage";      ///< OpenXR reference space of the poses
    double nominal_rate_hz = 90.0;
    std::string created;              ///< ISO 8601, informational
};

/// Raw non-hand input. Desktop mouse/keyboard and controller buttons (codes are GLFW key
/// and button codes) and panel settings. Unknown kinds in a file are skipped with a warning.
enum class InputEventKind : std::uint8_t {
    Key = 1,         ///< code = key, value = 1 press / 0 release
    MouseButton = 2, ///< code = button, value = 1 press / 0 release
    MouseMove = 3,   ///< x, y = cursor position in window pixels
    MouseWheel = 4,  ///< y = wheel delta
    Setting = 5,     ///< an appearance setting: code = SettingId, value = lobe id (0 = the whole tree), x = the number
    ImportMesh = 6,  ///< a mesh imported as a lobe at the fingertip: code = N ≥ 1, the mesh is the file
                     ///< import_mesh_path(recording, N) beside the recording
    Scene = 7,       ///< where the document sits in stage space changed (the VR app's two-handed grab):
                     ///< code = SceneComponent, x = its new value
};

/// What a Scene event sets (InputEvent::code): stage = R_y(yaw) · scale · document + translation.
/// Hand positions in stage space become document positions through the inverse (InputPipeline).
enum class SceneComponent : std::int32_t {
    Scale = 0,        ///< in [kMinSceneScale, kMaxSceneScale]
    Yaw = 1,          ///< radians about +Y, in [-4π, 4π]
    TranslationX = 2, ///< metres, |value| ≤ kMaxSceneTranslation
    TranslationY = 3,
    TranslationZ = 4,
};
inline constexpr float kMinSceneScale = 0.01f, kMaxSceneScale = 100.0f, kMaxSceneTranslation = 1000.0f;
/// The value is in the range of its component (readers drop Scene events outside it).
bool valid_scene_event(std::int32_t component, float value);

/// The mesh of ImportMesh event N of the recording at `recording_path`: a PLY file beside it,
/// "REC.import-N.ply" (the lobe mesh as imported: repaired, scaled, remeshed, centred on the
/// origin).
std::string import_mesh_path(const std::string& recording_path, int n);

/// What a Setting event sets (InputEvent::code). A reader skips an id it does not know with
/// a warning, like an unknown event kind. Ranges and units: docs/recording-format.md.
enum class SettingId : std::int32_t {
    SplitAngle = 1,       ///< degrees; tree-wide or per lobe (LobeRecord::split_angle_deg)
    AttractorSpacing = 2, ///< metres (settings.lobes.edge_length_m); tree-wide only
    LeafLength = 3,       ///< metres (settings.leaves.length_m; the width keeps its ratio); tree-wide only
    LeavesPerNode = 4,    ///< an integer (settings.leaves.per_node); tree-wide only
    Species = 5,          ///< an index into kSettingSpecies; tree-wide or per lobe (LobeRecord::species)
    Seed = 6,             ///< an integer in [1, 2^24) (Document::seed); tree-wide only
    Grower = 7,           ///< a grower's panel code (growth/grower.h); tree-wide only (trees[0].grower)
    GrowthSteps = 8,      ///< an integer ≥ 0: the scene grower's growth steps (Grower::steps_param), 0 for
                          ///< its default; tree-wide only
    // Appearance (ids from 20: a block of their own).
    LeafWidth = 20,    ///< metres (settings.leaves.width_m); tree-wide only
    LeafColor = 21,    ///< settings.leaves.color packed as 0xRRGGBB, each byte round(255 × linear component); tree-wide only
    BarkColor = 22,    ///< settings.branches.bark_color, packed as LeafColor; tree-wide only
    PipeExponent = 23, ///< settings.branches.pipe_exponent; tree-wide only
    TipRadius = 24,    ///< metres (settings.branches.tip_radius_m); tree-wide only
};

/// "split-angle", "attractor-spacing", "leaf-length", "leaves-per-node", "species", "seed",
/// "grower", "growth-steps", "leaf-width", "leaf-color", "bark-color", "pipe-exponent",
/// "tip-radius"; nullptr for an id this build does not know.
const char* setting_name(SettingId id);
inline bool known_setting_id(std::int32_t id) { return (id >= 1 && id <= 8) || (id >= 20 && id <= 24); }

/// A linear RGB colour (each component in [0, 1]) as a LeafColor/BarkColor value, and back.
int pack_color(const double (&rgb)[3]);
void unpack_color(int packed, double (&rgb)[3]);

/// The species a Setting event of id Species chooses from, by index (x = 0 … 3).
inline constexpr const char* kSettingSpecies[] = {"broadleaf", "conifer", "willow", "birch"};
inline constexpr int kSettingSpeciesCount = 4;

/// "key", "mouse_button", "mouse_move", "wheel", "setting", "import_mesh"; nullptr for a kind this build does not know.
const char* event_kind_name(InputEventKind kind);

struct InputEvent {
    double time = 0.0;
    InputEventKind kind = InputEventKind::Key;
    std::int32_t code = 0;
    std::int32_t value = 0;
    float x = 0.0f;
    float y = 0.0f;
};

/// A derived action written beside the raw input ("stroke_end id=3"): checked, never applied.
struct Annotation {
    double time = 0.0;
    std::string text;
};

struct Recording {
    RecordingHeader header;
    std::vector<HandFrame> frames;     ///< strictly increasing time
    std::vector<InputEvent> events;    ///< non-decreasing time
    std::vector<Annotation> annotations;
};

/// What the reader had to drop or repair, for the one-line messages the CLI prints.
struct ReadReport {
    std::size_t frames_read = 0;
    std::size_t frames_dropped = 0;
    std::size_t events_dropped = 0;
    std::vector<std::string> problems; ///< one line each, without the file name
};

/// Reads either form (detected by the first bytes). Recovers every complete, valid frame of
/// a truncated or partly corrupt file; frames with NaN/Inf or absurd coordinates, or with
/// time going backwards, are dropped and counted in the report.
/// \throw FileError (one line, naming the file) when the file is missing, has a wrong magic
///        or unsupported version, or no usable frame remains.
Recording read_recording(const std::string& path, ReadReport* report = nullptr);

/// Parses a recording held in memory (both forms); `name` stands for the file in messages.
/// \throw FileError as read_recording.
Recording parse_recording(const std::string& bytes, const std::string& name, ReadReport* report = nullptr);

/// Whole-file writers (atomic: temporary file, flush, rename). Frames, events and
/// annotations are written merged by time (ties: frame, event, annotation); annotation texts
/// are clipped to 1,000 bytes.
/// \throw FileError when the file cannot be written (the previous file is then untouched);
///        InvalidInput (binary form) when the header's JSON exceeds 64 KiB.
void write_recording_binary(const std::string& path, const Recording& rec);
void write_recording_text(const std::string& path, const Recording& rec);
/// The bytes the writers above write. \throw InvalidInput (binary form) as above.
std::string encode_recording_binary(const Recording& rec);
std::string encode_recording_text(const Recording& rec);

/// Streaming writer for live sessions: appends and flushes every `flush_every` frames (1 =
/// every frame), so a crash loses at most the frames not yet flushed; the file is readable up
/// to its last complete record at any moment.
class RecordingWriter {
public:
    /// Creates (or truncates) `path` and writes the file header (binary form).
    /// \throw FileError when the file cannot be created or written; InvalidInput when the
    ///        header's JSON exceeds 64 KiB.
    RecordingWriter(const std::string& path, const RecordingHeader& header, int flush_every = 1);
    /// Closes the file; write errors are swallowed here (call close() to see them).
    ~RecordingWriter();
    RecordingWriter(const RecordingWriter&) = delete;
    RecordingWriter& operator=(const RecordingWriter&) = delete;

    /// Appends one record. Frames are flushed every `flush_every`, events and annotations at
    /// once. \throw FileError on a write error or after close().
    void append(const HandFrame& frame);
    void append(const InputEvent& event);
    void append(const Annotation& annotation);
    /// \throw FileError on a flush error or after close().
    void flush();
    /// Flushes, syncs to disk and closes; a second call does nothing.
    /// \throw FileError when any of these fails.
    void close();
    const std::string& path() const { return path_; }

private:
    void write_bytes(const std::string& bytes);
    std::string path_;
    std::FILE* file_ = nullptr;
    int flush_every_ = 1;
    int pending_ = 0;
};

} // namespace lobe
