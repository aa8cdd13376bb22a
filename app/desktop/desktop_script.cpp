#include "app/desktop/desktop_script.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "app/desktop/desktop_session.h"
#include "app/live/lsystem_sketch_mode.h"
#include "core/errors.h"
#include "input/tools.h"

namespace lobe {

namespace {

constexpr std::size_t kMaxSteps = 200000;
constexpr int kMaxFrame = 10000000;
constexpr int kMaxMacroFrames = 100000;
constexpr double kMaxPixel = 1e6;         ///< |x|, |y| of a cursor position, a circle's radius
constexpr double kMaxNotches = 1e4;       ///< |wheel notches| of one step
constexpr double kMaxSettingValue = 1e9;  ///< |value| of `set` (validated again when applied)

std::string lower(std::string s)
{
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

int mouse_button_code(const std::string& name)
{
    if (name == "left") return desktop_keys::kMouseLeft;
    if (name == "right") return desktop_keys::kMouseRight;
    if (name == "middle") return desktop_keys::kMouseMiddle;
    return -1;
}

/// GLFW key code of a key name: a letter or digit, or one of the named keys.
int key_code(const std::string& name_in)
{
    const std::string name = lower(name_in);
    if (name.size() == 1 && std::isalnum(static_cast<unsigned char>(name[0])))
        return std::toupper(static_cast<unsigned char>(name[0]));
    static const std::pair<const char*, int> named[] = {
        {"escape", 256}, {"enter", 257}, {"tab", 258}, {"backspace", 259}, {"delete", 261},
        {"shift", 340},  {"space", 32},  {"f1", 290},  {"f2", 291},        {"home", 268},
        {"comma", 44},   {"period", 46}, {"minus", 45}, {"equal", 61},     {"leftbracket", 91}, {"rightbracket", 93},
    };
    for (const auto& [n, code] : named)
        if (name == n) return code;
    return -1;
}

} // namespace

const std::vector<PanelAction>& panel_actions()
{
    static const std::vector<PanelAction> actions = {
        {"draw-lobe", "Lobes (L)", keys::kDrawLobe},
        {"draw-trunk", "Trunk (T)", keys::kDrawTrunk},
        {"grow", "Grow (G)", keys::kGrow},
        {"new-lobe", "New lobe (N)", keys::kNewLobe},
        {"deform", "Pinch lobe (D)", keys::kDeformLobe},
        {"edit-stroke", "Bend stroke (E)", keys::kEditStroke},
        {"move", "Move lobe (M)", keys::kMoveLobe},
        {"rotate", "Rotate lobe (R)", keys::kRotateLobe},
        {"scale", "Scale lobe (K)", keys::kScaleLobe},
        {"undo", "Undo (Z)", keys::kUndo},
        {"redo", "Redo (Y)", keys::kRedo},
        {"delete-stroke", "Del stroke (Bksp)", keys::kDeleteStroke},
        {"delete-lobe", "Del lobe (Del)", keys::kDeleteLobe},
        {"duplicate", "Duplicate (C)", keys::kDuplicate},
        {"mirror", "Mirror (X)", keys::kMirror},
        {"save", "Save (S)", desktop_keys::kSave},
        {"export", "Export (W)", desktop_keys::kExport},
        {"frame", "Frame (F)", desktop_keys::kFrame},
        // The L-system sketch mode (docs/lsystem-sketch.md); its other keys act while it is on.
        {"lsystem", "L-system (P)", keys::kLSystemSketch},
        {"lsystem-branch", "Branch (B)", lsystem_sketch_keys::kBranch},
    };
    return actions;
}

int panel_action_key(const std::string& name)
{
    for (const PanelAction& a : panel_actions())
        if (name == a.name) return a.key;
    return -1;
}

const std::vector<PanelSetting>& panel_settings()
{
    static const std::vector<PanelSetting> settings = {
        {"split-angle", static_cast<int>(SettingId::SplitAngle)},
        {"spacing", static_cast<int>(SettingId::AttractorSpacing)},
        {"leaf-size", static_cast<int>(SettingId::LeafLength)},
        {"leaves", static_cast<int>(SettingId::LeavesPerNode)},
        {"species", static_cast<int>(SettingId::Species)},
        {"seed", static_cast<int>(SettingId::Seed)},
        {"grower", static_cast<int>(SettingId::Grower)},
        {"growth-steps", static_cast<int>(SettingId::GrowthSteps)},
        {"leaf-width", static_cast<int>(SettingId::LeafWidth)},
        {"leaf-color", static_cast<int>(SettingId::LeafColor)},
        {"bark-color", static_cast<int>(SettingId::BarkColor)},
        {"pipe-exponent", static_cast<int>(SettingId::PipeExponent)},
        {"tip-radius", static_cast<int>(SettingId::TipRadius)},
    };
    return settings;
}

namespace {

/// One script being read: the steps so far, the line being read and its words.
class ScriptParser {
public:
    explicit ScriptParser(const std::string& name) : name_(name) {}

    std::vector<ScriptStep> parse(const std::string& text)
    {
        std::istringstream in(text);
        std::string raw;
        while (std::getline(in, raw)) {
            ++line_no_;
            if (const auto hash = raw.find('#'); hash != std::string::npos) raw.resize(hash);
            std::istringstream ls(raw);
            w_.clear();
            for (std::string t; ls >> t;) w_.push_back(t);
            if (!w_.empty()) line();
        }
        std::stable_sort(steps_.begin(), steps_.end(),
                         [](const ScriptStep& a, const ScriptStep& b) { return a.frame < b.frame; });
        return std::move(steps_);
    }

private:
    [[noreturn]] void fail(const std::string& what) const
    {
        throw InvalidInput(name_ + ":" + std::to_string(line_no_) + ": " + what);
    }

    void push(ScriptStep s)
    {
        if (steps_.size() >= kMaxSteps) fail("more than " + std::to_string(kMaxSteps) + " steps");
        s.line = line_no_;
        steps_.push_back(std::move(s));
    }

    double number(std::size_t i, const char* what) const
    {
        if (i >= w_.size()) fail(std::string("missing ") + what);
        std::size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(w_[i], &used);
        } catch (...) {
            used = 0;
        }
        if (used != w_[i].size() || !std::isfinite(v)) fail(std::string("bad ") + what + " '" + w_[i] + "'");
        return v;
    }

    /// Pixels, notches and setting values become the floats of input events: a number beyond
    /// these bounds would not fit (and no window or setting needs it).
    double bounded(std::size_t i, const char* what, double limit) const
    {
        const double v = number(i, what);
        if (std::abs(v) > limit) fail(std::string(what) + " '" + w_[i] + "' is out of range");
        return v;
    }

    void expect_args(std::size_t lo, std::size_t hi) const
    {
        if (w_.size() - 2 < lo || w_.size() - 2 > hi)
            fail("'" + cmd_ + "' takes " + std::to_string(lo) + (hi > lo ? " to " + std::to_string(hi) : "") +
                 " argument(s)");
    }

    void line()
    {
        const double f = number(0, "frame number");
        if (f < 0 || f > kMaxFrame || f != std::floor(f)) fail("frame '" + w_[0] + "' is not a whole number in 0..10^7");
        const int frame = static_cast<int>(f);
        if (frame < last_frame_) fail("frame " + w_[0] + " comes before frame " + std::to_string(last_frame_));
        last_frame_ = frame;
        if (w_.size() < 2) fail("missing command");
        cmd_ = lower(w_[1]);
        ScriptStep s;
        s.frame = frame;
        if (cmd_ == "move" || cmd_ == "down" || cmd_ == "up" || cmd_ == "wheel") pointer(s);
        else if (cmd_ == "key" || cmd_ == "press" || cmd_ == "release") key(s);
        else if (cmd_ == "ui") panel(s);
        else if (cmd_ == "set") setting(s);
        else if (cmd_ == "import") import(s);
        else if (cmd_ == "wait" || cmd_ == "quit" || cmd_ == "mark") control(s);
        else if (cmd_ == "circle" || cmd_ == "line") macro(frame);
        else
            fail("unknown command '" + w_[1] + "' (move, down, up, wheel, key, press, release, ui, set, wait, mark, quit, "
                 "circle, line)");
    }

    void pointer(ScriptStep& s)
    {
        if (cmd_ == "move") {
            expect_args(2, 2);
            s.kind = ScriptStep::Kind::Move;
            s.x = float(bounded(2, "x", kMaxPixel));
            s.y = float(bounded(3, "y", kMaxPixel));
        } else if (cmd_ == "wheel") {
            expect_args(1, 1);
            s.kind = ScriptStep::Kind::Wheel;
            s.y = float(bounded(2, "wheel notches", kMaxNotches));
        } else {
            expect_args(1, 1);
            s.kind = cmd_ == "down" ? ScriptStep::Kind::Down : ScriptStep::Kind::Up;
            s.code = mouse_button_code(lower(w_[2]));
            if (s.code < 0) fail("unknown mouse button '" + w_[2] + "' (left, right, middle)");
        }
        push(s);
    }

    void key(ScriptStep& s)
    {
        expect_args(1, 1);
        s.code = key_code(w_[2]);
        if (s.code < 0) fail("unknown key '" + w_[2] + "'");
        if (cmd_ != "release") {
            s.kind = ScriptStep::Kind::KeyPress;
            push(s);
        }
        if (cmd_ != "press") {
            s.kind = ScriptStep::Kind::KeyRelease;
            push(s);
        }
    }

    void panel(ScriptStep& s)
    {
        expect_args(1, 1);
        if (panel_action_key(lower(w_[2])) < 0) fail("unknown panel action '" + w_[2] + "'");
        s.kind = ScriptStep::Kind::Panel;
        s.name = lower(w_[2]);
        push(s);
    }

    void setting(ScriptStep& s)
    {
        expect_args(2, 4);
        s.kind = ScriptStep::Kind::Set;
        s.code = -1;
        for (const PanelSetting& p : panel_settings())
            if (lower(w_[2]) == p.name) s.code = p.id;
        if (s.code < 0) fail("unknown setting '" + w_[2] + "'");
        s.value = bounded(3, "setting value", kMaxSettingValue);
        if (w_.size() == 6) {
            if (lower(w_[4]) != "lobe") fail("expected 'lobe ID' after the value");
            const double id = number(5, "lobe id");
            if (id < 1 || id > 1e9 || id != std::floor(id)) fail("bad lobe id '" + w_[5] + "'");
            s.lobe = static_cast<std::int64_t>(id);
        } else if (w_.size() != 4) {
            fail("expected 'set NAME VALUE [lobe ID]'");
        }
        push(s);
    }

    void import(ScriptStep& s)
    {
        expect_args(1, 2);
        s.kind = ScriptStep::Kind::Import;
        s.name = w_[2];
        s.value = w_.size() == 4 ? number(3, "size") : 1.5;
        if (!(s.value > 0.01 && s.value <= 100.0)) fail("the size must be in (0.01, 100] m");
        push(s);
    }

    void control(ScriptStep& s)
    {
        if (cmd_ == "mark") {
            expect_args(1, 1);
            s.kind = ScriptStep::Kind::Mark;
            s.name = w_[2];
        } else {
            expect_args(0, 0);
            s.kind = cmd_ == "wait" ? ScriptStep::Kind::Wait : ScriptStep::Kind::Quit;
        }
        push(s);
    }

    /// circle CX CY R FRAMES [BUTTON]: one turn and a little more, so the ends overlap;
    /// line X0 Y0 X1 Y1 FRAMES [BUTTON]. The button is pressed after the first move and
    /// released after the last; with BUTTON `none` the cursor only glides (a jump of the
    /// fingertip between two frames reads as a tracking glitch, as it would in VR).
    void macro(int frame)
    {
        const bool circle = cmd_ == "circle";
        const std::size_t n_num = circle ? 4 : 5;
        expect_args(n_num, n_num + 1);
        std::vector<double> a;
        for (std::size_t i = 0; i + 1 < n_num; ++i) a.push_back(bounded(2 + i, "coordinate", kMaxPixel));
        a.push_back(number(2 + n_num - 1, "frame count"));
        const double frames_d = a.back();
        if (frames_d < 2 || frames_d > kMaxMacroFrames || frames_d != std::floor(frames_d))
            fail("the frame count of '" + cmd_ + "' must be a whole number in 2..100000");
        const int frames = static_cast<int>(frames_d);
        if (frame + frames + 1 > kMaxFrame) fail("the macro runs past frame 10^7");
        int button = desktop_keys::kMouseLeft;
        if (w_.size() == 2 + n_num + 1) {
            button = lower(w_.back()) == "none" ? -2 : mouse_button_code(lower(w_.back()));
            if (button == -1) fail("unknown mouse button '" + w_.back() + "' (left, right, middle, none)");
        }
        auto at = [&](double u, float& x, float& y) {
            if (circle) {
                const double ang = u * 2.0 * 3.14159265358979323846 * 1.06;
                x = float(a[0] + a[2] * std::cos(ang));
                y = float(a[1] - a[2] * std::sin(ang));
            } else {
                x = float(a[0] + (a[2] - a[0]) * u);
                y = float(a[1] + (a[3] - a[1]) * u);
            }
        };
        ScriptStep m;
        m.kind = ScriptStep::Kind::Move;
        m.frame = frame;
        at(0.0, m.x, m.y);
        push(m);
        ScriptStep d;
        d.kind = ScriptStep::Kind::Down;
        d.code = button;
        d.frame = frame + 1;
        if (button >= 0) push(d); // "none": the cursor glides with no button held
        for (int i = 1; i <= frames; ++i) {
            m.frame = frame + 1 + i;
            at(double(i) / frames, m.x, m.y);
            push(m);
        }
        d.kind = ScriptStep::Kind::Up;
        d.frame = frame + frames + 2;
        if (button >= 0) push(d);
        last_frame_ = frame; // later lines may not come before this macro's start
    }

    const std::string& name_;
    std::vector<ScriptStep> steps_;
    std::vector<std::string> w_; ///< the words of the line being read
    std::string cmd_;            ///< its command, lower case
    int line_no_ = 0, last_frame_ = 0;
};

} // namespace

std::vector<ScriptStep> parse_desktop_script(const std::string& text, const std::string& name)
{
    return ScriptParser(name).parse(text);
}

} // namespace lobe
