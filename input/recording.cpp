// Reading a recording: the form is told by its first bytes, then read by
// recording_binary.cpp or recording_text.cpp; writing is in recording_writer.cpp. Both
// forms byte by byte and line by line: docs/recording-format.md.
#include "input/recording.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/recording_format.h"

namespace lobe {

using namespace recording_format;

Recording parse_recording(const std::string& bytes, const std::string& name, ReadReport* report)
{
    ReadReport local;
    ReadReport& r = report ? *report : local;
    r = ReadReport{};
    std::string_view data(bytes);
    if (data.empty()) throw FileError(name, "empty file");
    const std::string_view magic(reinterpret_cast<const char*>(kMagic.data()), kMagic.size());
    if (starts_with(data, magic)) return parse_binary(data, name, r);
    if (data.size() < magic.size() && starts_with(magic, data))
        throw FileError(name, "truncated file header (" + std::to_string(data.size()) + " bytes)");
    std::string_view text = starts_with(data, kUtf8Bom) ? data.substr(kUtf8Bom.size()) : data;
    if (starts_with(text, kTextMagic) &&
        (text.size() == kTextMagic.size() || is_space(text[kTextMagic.size()]) || text[kTextMagic.size()] == '\n'))
        return parse_text(data, name, r);
    throw FileError(name, "not a Lobesketch recording (wrong magic bytes)");
}

Recording read_recording(const std::string& path, ReadReport* report)
{
    return parse_recording(read_file_limited(path, kMaxFileBytes), path, report);
}

bool valid_scene_event(std::int32_t component, float value)
{
    if (!std::isfinite(value)) return false;
    switch (static_cast<SceneComponent>(component)) {
    case SceneComponent::Scale: return value >= kMinSceneScale && value <= kMaxSceneScale;
    case SceneComponent::Yaw: return std::abs(value) <= 4.0f * 3.14159265f;
    case SceneComponent::TranslationX:
    case SceneComponent::TranslationY:
    case SceneComponent::TranslationZ: return std::abs(value) <= kMaxSceneTranslation;
    }
    return false;
}

std::string import_mesh_path(const std::string& recording_path, int n)
{
    return recording_path + ".import-" + std::to_string(n) + ".ply";
}

const char* event_kind_name(InputEventKind k)
{
    switch (k) {
    case InputEventKind::Key: return "key";
    case InputEventKind::MouseButton: return "mouse_button";
    case InputEventKind::MouseMove: return "mouse_move";
    case InputEventKind::MouseWheel: return "wheel";
    case InputEventKind::Setting: return "setting";
    case InputEventKind::ImportMesh: return "import_mesh";
    case InputEventKind::Scene: return "scene";
    }
    return nullptr;
}

const char* setting_name(SettingId id)
{
    switch (id) {
    case SettingId::SplitAngle: return "split-angle";
    case SettingId::AttractorSpacing: return "attractor-spacing";
    case SettingId::LeafLength: return "leaf-length";
    case SettingId::LeavesPerNode: return "leaves-per-node";
    case SettingId::Species: return "species";
    case SettingId::Seed: return "seed";
    case SettingId::Grower: return "grower";
    case SettingId::GrowthSteps: return "growth-steps";
    case SettingId::LeafWidth: return "leaf-width";
    case SettingId::LeafColor: return "leaf-color";
    case SettingId::BarkColor: return "bark-color";
    case SettingId::PipeExponent: return "pipe-exponent";
    case SettingId::TipRadius: return "tip-radius";
    }
    return nullptr;
}

int pack_color(const double (&rgb)[3])
{
    int packed = 0;
    for (double c : rgb) packed = packed * 256 + static_cast<int>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
    return packed;
}

void unpack_color(int packed, double (&rgb)[3])
{
    for (int i = 2; i >= 0; --i) {
        rgb[i] = double(packed & 255) / 255.0;
        packed >>= 8;
    }
}

} // namespace lobe
