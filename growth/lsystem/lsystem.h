#pragma once
/// \file lsystem.h
/// L-systems in the language of *The Algorithmic Beauty of Plants* (Prusinkiewicz and
/// Lindenmayer 1990, "ABOP") and its program cpfg: bracketed, stochastic, parametric and
/// context-sensitive productions rewritten in parallel, with decomposition and homomorphism
/// sections, `#define` constants and the cut symbol `%`. docs/lsystems.md lists exactly what
/// of cpfg's language is read; growth/lsystem/turtle.h draws a derived word as a tree.
///
/// Everything here is deterministic for a seed (core/random.h), whatever the compiler.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace lobe::lsystem {

/// A module's name, interned per LSystem: one printable ASCII character (`F`, `+`, `[`, `A`),
/// or `@` or `?` followed by one letter (`@o`, `@v`, `?P`, `?E`; also cpfg's `@Gs`, `@Dd`,
/// `@Tx`: `@G`, `@D`, `@T` take one more lower-case letter). Not modules: `*` (no context, no
/// condition, the empty successor), `<` `>` `:` `(` `)`; a line starting with `#` is a
/// preprocessor line.
using SymbolId = std::uint16_t;

/// Most modules a word may hold, and most parameter values (all modules together); a
/// derivation that would pass either stops with InvalidInput naming the step. Two words are
/// alive during a step, so memory stays under about 0.6 GB at the limits.
inline constexpr std::size_t kMaxModules = std::size_t{1} << 24;     // 16,777,216
inline constexpr std::size_t kMaxParamValues = std::size_t{1} << 24; // 16,777,216
/// Most parameters one module carries.
inline constexpr std::size_t kMaxModuleParams = 255;
/// Most derivation steps a file or a command may ask for.
inline constexpr int kMaxDerivationLength = 100000;
/// Most bytes of a `.l` or `.v` file.
inline constexpr std::size_t kMaxFileBytes = std::size_t{8} << 20;

/// One module of a word: its name and where its parameters are in Word::params.
struct Module {
    SymbolId symbol = 0;
    std::uint16_t param_count = 0;
    std::uint32_t first_param = 0;
};

/// A word (an L-system string): modules in order and their parameter values, flat.
struct Word {
    std::vector<Module> modules;
    std::vector<double> params;

    std::size_t size() const { return modules.size(); }
    bool empty() const { return modules.empty(); }
    std::span<const double> params_of(const Module& m) const
    {
        return {params.data() + m.first_param, m.param_count};
    }
    std::span<double> params_of(const Module& m) { return {params.data() + m.first_param, m.param_count}; }
    /// Appends a module with `values` as its parameters.
    /// \throw InvalidInput for more than kMaxModuleParams values.
    void push(SymbolId symbol, std::span<const double> values = {});
    void clear()
    {
        modules.clear();
        params.clear();
    }
};

/// What the view file (`NAME.v` beside `NAME.l`) sets for the turtle; defaults as cpfg's.
struct ViewSettings {
    double angle_increment_deg = 45.0; ///< `angle increment:` (or 360 / `angle factor:`)
    double initial_line_width = 1.0;   ///< `initial line width:`, in width_unit
    /// What a width is measured in. cpfg draws widths in screen pixels unless the view file
    /// says `initial line width: W polygons` or `line style: polygon` / `cylinder`, when they
    /// are in the model's units (turtle.h says how pixels become metres).
    enum class WidthUnit : std::uint8_t { Pixels, Model };
    WidthUnit width_unit = WidthUnit::Pixels;
    double line_width_increment = 1.0; ///< `line width increment:`, the step of `!` and `#` without a parameter
    double scale_factor = 1.0;         ///< `scale factor:`, multiplies the drawn model
    glm::dvec3 tropism_direction{0.0, -1.0, 0.0}; ///< `tropism direction:` (normalised when read)
    double elasticity = 0.0;           ///< `initial elasticity:` / `tropism ... elasticity` (e)
    double elasticity_increment = 0.0; ///< `elasticity increment:`
    bool tropism = false;              ///< a tropism line was given
    /// `metres per unit:` (a Lobesketch line, not cpfg's): when > 0 the model is drawn at
    /// this scale, metres per model unit, instead of being fitted to a height (the L-system
    /// grower); 0, the default, fits it.
    double metres_per_unit = 0.0;
};

/// Where a tree may grow: answers the turtle's position queries for the model's environment
/// functions (`inside(x, y, z)` in expressions, `?E` modules). Coordinates are the turtle's
/// model units.
class Environment {
public:
    virtual ~Environment() = default;
    /// Whether `p` lies inside the space the tree may fill (a lobe, a topiary shape).
    virtual bool inside(const glm::dvec3& p) const = 0;
};

/// A parsed and compiled L-system (a `.l` file). Cheap to copy (shared, immutable).
class LSystem {
public:
    struct Impl;

    LSystem();
    explicit LSystem(std::shared_ptr<const Impl> impl);

    /// The file or name it was read from (for messages).
    const std::string& source_name() const;
    /// `derivation length:` (0 when the file has none).
    int derivation_length() const;
    /// The axiom, its parameters evaluated.
    const Word& axiom() const;
    /// The id of `name`, or nullopt-like -1 when the system never mentions it.
    int find_symbol(std::string_view name) const;
    /// The name of a symbol id of this system.
    std::string_view symbol_name(SymbolId id) const;
    std::size_t symbol_count() const;
    /// Whether any production or the axiom holds a query module (`?P`, `?H`, `?L`, `?U`,
    /// `?E`): derive() then asks its DeriveOptions::answer_queries after every step.
    bool has_queries() const;

    const Impl& impl() const { return *impl_; }

private:
    std::shared_ptr<const Impl> impl_;
};

/// Reads a `.l` file's text. Unsupported cpfg features give one warning line each (in
/// `warnings`, "NAME:LINE:COL: …", at most 200 and then one line counting the rest) and a
/// stand-in (docs/lsystems.md): statement blocks `{…}` are skipped, `func()` gives 1 and
/// cpfg's other functions 0, `-o>` reads as `-->`, `seed:` and a second L-system are ignored.
/// `#define NAME value` defines a constant, expanded where used as a parenthesised expression;
/// `/* */` comments anywhere, `//` comments where `//` starts a line or stands between blanks
/// (elsewhere `//` is two rolls). Expressions: expr.h (trigonometry in degrees).
/// \throw InvalidInput "NAME:LINE:COL: …", one line, for anything malformed: unbalanced
/// brackets, an unknown or malformed production, an undefined constant, a recursive
/// `#define`, a constant division by zero, expressions nested over 100 levels, a derivation
/// length over kMaxDerivationLength, a file over kMaxFileBytes.
LSystem parse_lsystem(std::string_view text, const std::string& source_name,
                      std::vector<std::string>* warnings = nullptr);

/// Reads a view file's text (cpfg's `.v`): the lines of ViewSettings; every other line gives
/// one warning and is skipped. \throw InvalidInput "NAME:LINE:COL: …" for a malformed value.
ViewSettings parse_view(std::string_view text, const std::string& source_name,
                        std::vector<std::string>* warnings = nullptr);

/// A `.l` file and its view file.
struct LSystemFile {
    LSystem system;
    ViewSettings view;      ///< from `NAME.v` beside `NAME.l` when present, else defaults
    bool has_view = false;
    std::vector<std::string> warnings;
};

/// Reads `path` and, when present, the view file of the same name beside it.
/// \throw FileError when a file cannot be read; InvalidInput as parse_lsystem/parse_view.
LSystemFile load_lsystem_file(const std::filesystem::path& path);

struct DeriveOptions {
    /// Derivation steps; -1 takes the file's `derivation length:`.
    int steps = -1;
    std::uint64_t seed = 1; ///< keys stochastic productions, ran() and nran()
    std::size_t max_modules = kMaxModules;
    std::size_t max_param_values = kMaxParamValues;
    /// Most work one call may do: modules visited and written plus expression instructions
    /// run (about 30 s of one core at the default); past it InvalidInput naming the step, so
    /// that a file whose productions evaluate huge expressions over a huge word cannot hang.
    std::uint64_t max_operations = std::uint64_t{1} << 35;
    /// Where `inside(x, y, z)` and `?E` look; null: everywhere is inside.
    const Environment* environment = nullptr;
    /// Fills the parameters of the query modules of `word` (`?P(x, y, z)` the turtle's
    /// position, `?H`/`?L`/`?U` its vectors, `?E(v)` 1 inside the environment, else 0) by
    /// interpreting it; called before the first step and after every step when
    /// LSystem::has_queries(). Null: queries keep the values their productions wrote.
    std::function<void(Word& word)> answer_queries;
};

/// Rewrites the axiom `steps` times in parallel; after each step applies the decomposition
/// productions (up to their `maximum depth:`, cpfg's default 1) and then the cut symbol (`%`
/// and the rest of its branch are removed). Context-sensitive productions are tried before
/// context-free ones, each kind in file order: the first that matches (predecessor and
/// parameter count, context, condition) applies, or, when any of that kind carries a
/// probability, one of those that match chosen by weight (normalised, as cpfg does; no
/// probability counts 1). Context is bracket-aware as in ABOP: a branch's first module sees
/// the module before the branch, earlier branches are skipped, a right context skips whole
/// branches and stops at the end of its own unless it names brackets (`A > [B]C`); the
/// `ignore:`/`consider:` modules are skipped. Random numbers (choices, ran, nran) are keyed by
/// the seed, the step and the module's position: the same seed gives the same word.
/// \throw InvalidInput, one line naming the step and the module, for a word past
/// max_modules / max_param_values, a division by zero or another failed evaluation.
Word derive(const LSystem& system, const DeriveOptions& options = {});

/// One derivation step of `in` into `out` (cut and decomposition included, then
/// answer_queries when the system has queries); `step` (1 for the first) keys the random
/// numbers and names the step in messages. For callers that show growth step by step.
/// \throw InvalidInput as derive(), and for a module of `in` that is not of this system.
void derive_step(const LSystem& system, const Word& in, Word& out, int step, const DeriveOptions& options);

/// The word the turtle draws: the homomorphism productions applied (up to their
/// `maximum depth:`); the word itself when the system has none.
Word interpretation_word(const LSystem& system, const Word& word, std::uint64_t seed = 1);
/// As above, with `options.seed` and the limits of `options` (max_modules, max_param_values,
/// max_operations); steps, environment and answer_queries are not used.
/// \throw InvalidInput past the limits or for a failed evaluation ("NAME: step 0: …").
Word interpretation_word(const LSystem& system, const Word& word, const DeriveOptions& options);

/// The word as text, as cpfg writes it: `F(1.5)[+(30)A]B`, numbers in shortest form.
std::string to_string(const LSystem& system, const Word& word);

} // namespace lobe::lsystem
