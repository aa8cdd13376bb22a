// Reading cpfg's `.l` (L-system) and `.v` (view) files: lsystem.h.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_set>

#include "core/errors.h"
#include "growth/lsystem/expr.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/lsystem_impl.h"
#include "growth/lsystem/lsystem_text.h"

namespace lobe::lsystem {

std::string detail::blank_comments(std::string_view text, const SourceText& src)
{
    std::string out(text);
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
        const char c = out[i];
        if (c == '\n') {
            line_start = i + 1;
            continue;
        }
        if (c != '/' || i + 1 >= out.size()) continue;
        if (out[i + 1] == '*') {
            const std::size_t close = out.find("*/", i + 2);
            if (close == std::string::npos) src.fail(i, "unterminated comment '/*'");
            for (std::size_t k = i; k < close + 2; ++k)
                if (out[k] != '\n') out[k] = ' ';
            i = close + 1;
            continue;
        }
        if (out[i + 1] == '/') {
            bool at_line_start = true;
            for (std::size_t k = line_start; k < i; ++k)
                if (!is_blank(out[k])) at_line_start = false;
            const bool blank_before = i > 0 && is_blank(out[i - 1]);
            const bool blank_after = i + 2 >= out.size() || is_blank(out[i + 2]);
            if (at_line_start || (blank_before && blank_after)) {
                std::size_t k = i;
                while (k < out.size() && out[k] != '\n') out[k++] = ' ';
                i = k - 1;
            }
        }
    }
    return out;
}


namespace {

using detail::Expr;
using detail::PatternModule;
using detail::Production;
using detail::ProductionSet;
using detail::SourceText;
using detail::SuccessorModule;
using detail::Warnings;
using detail::is_blank;
using detail::is_letter;
using detail::is_name_char;
using detail::is_name_start;
using detail::lower;
using detail::number_text;
using detail::shorten;

/// The parser of one `.l` file.
class LParser {
public:
    LParser(std::string_view text, const std::string& name, std::vector<std::string>* warnings)
        : original_(text), name_(name), warnings_(warnings), raw_(text, name)
    {
    }

    std::shared_ptr<const LSystem::Impl> run();

private:
    /// What the lines read so far have set.
    struct State {
        bool seen_header = false;
        bool seen_axiom = false;
        bool ended = false;
        bool warned_after_end = false;
        std::vector<SymbolId> ignore_list;
        std::vector<SymbolId> consider_list;
        int context_list = 0; ///< 0 none, 1 ignore, 2 consider
        std::size_t last_offset = 0;
    };

    struct Line {
        std::size_t begin;
        std::size_t end;
    };

    void warn(std::size_t offset, const std::string& message) { warnings_.add(src().where(offset) + message); }
    const SourceText& src() const { return *src_; }
    std::string_view text() const { return clean_; }
    std::size_t skip_blanks(std::size_t p, std::size_t end) const
    {
        while (p < end && is_blank(clean_[p])) ++p;
        return p;
    }
    std::size_t trim_end(std::size_t begin, std::size_t end) const
    {
        while (end > begin && is_blank(clean_[end - 1])) --end;
        return end;
    }

    /// Comments blanked, lines split, #defines collected and checked.
    void prepare();
    /// Line `i` (moved past the lines a block or a production continues over).
    void read_line(std::size_t& i);
    /// A keyword line (`derivation length:`, `Axiom:`, a section, a block…) starting at `p`;
    /// false when line `i` is none, i.e. a production.
    bool read_statement(std::size_t& i, std::size_t p);
    void parse_axiom(std::size_t p, std::size_t after, std::size_t line_end);
    /// `homomorphism` or `decomposition` (optionally `: warnings`).
    void start_section(std::size_t p, std::size_t after, std::size_t line_end);
    /// Where the production starting at `p` on line `i` ends; `i` moves to its last line.
    std::size_t production_end(std::size_t& i, std::size_t p) const;
    /// Checks after the last line, the context tables, the production index.
    void finish();
    void split_lines();
    void collect_defines();
    /// Whether line `i` starts with `keyword` (letters case-insensitive, blanks within the
    /// keyword optional); sets `after` to the offset after it.
    bool keyword(const Line& line, std::string_view keyword, std::size_t& after) const;
    void skip_block(std::size_t& i, std::size_t from, const char* what);

    SymbolId intern(std::string_view name, std::size_t offset);
    /// Reads one module name at `p` (a character, `?X`, `@X`); moves `p` past it.
    std::string_view read_symbol(std::size_t& p, std::size_t end);
    /// The parenthesised list after a module's name at `p`, when there is one: `item(p)` reads
    /// one entry and leaves `p` after it; ',' separates, ')' ends; `p` moves past the list.
    template <class Item>
    void read_parameter_list(std::size_t& p, std::size_t end, const std::string& unclosed, const char* kind, Item&& item);
    /// Modules with parameter expressions (axiom, successor). Appends to `out`.
    void parse_modules(std::size_t begin, std::size_t end, std::vector<SuccessorModule>& out,
                       std::vector<Expr>& exprs, const char* what);
    /// Modules with formal parameters (predecessor, contexts).
    void parse_pattern(std::size_t begin, std::size_t end, std::vector<PatternModule>& out,
                       std::unordered_map<std::string, std::uint32_t>& scope, std::vector<std::size_t>& offsets);
    void parse_symbol_list(std::size_t begin, std::size_t end, std::vector<SymbolId>& out);
    using Scope = std::unordered_map<std::string, std::uint32_t>;
    /// `lc < pred > rc : cond --> succ : prob` in [begin, end).
    void parse_production(std::size_t begin, std::size_t end);
    /// The arrow of the production in [begin, end) and the offset after it; npos when none.
    std::pair<std::size_t, std::size_t> find_arrow(std::size_t begin, std::size_t end) const;
    /// `lc < pred > rc` in [begin, ctx_end): the formal parameters go into `scope`.
    void parse_left_side(Production& prod, std::size_t begin, std::size_t ctx_end, Scope& scope);
    /// The condition after the ':' at `colon`, up to the arrow.
    void parse_condition(Production& prod, std::size_t colon, std::size_t arrow);
    /// `succ : prob` from after the arrow to `end`.
    void parse_right_side(Production& prod, std::size_t arrow_end, std::size_t end);
    void check_brackets(const std::vector<SuccessorModule>& modules, std::size_t offset, const char* what) const;
    double constant_value(std::size_t begin, std::size_t end, const char* what);
    void finish_probability_groups();

    std::string_view original_;
    std::string name_;
    Warnings warnings_;
    SourceText raw_;
    std::string clean_;
    std::unique_ptr<SourceText> src_;
    std::vector<Line> lines_;
    std::unordered_map<std::string, detail::Define> defines_;
    std::shared_ptr<LSystem::Impl> sys_ = std::make_shared<LSystem::Impl>();
    std::unique_ptr<detail::ExprCompiler> compiler_;
    ProductionSet* section_ = nullptr;
    State state_;
    struct GroupEntry {
        std::string key;
        double probability;
        std::size_t offset;
        bool constant;
    };
    std::vector<GroupEntry> groups_;
};

void LParser::split_lines()
{
    std::size_t b = 0;
    for (std::size_t i = 0; i <= clean_.size(); ++i) {
        if (i == clean_.size() || clean_[i] == '\n') {
            lines_.push_back({b, i});
            b = i + 1;
        }
    }
}

bool LParser::keyword(const Line& line, std::string_view kw, std::size_t& after) const
{
    std::size_t p = skip_blanks(line.begin, line.end);
    for (const char k : kw) {
        if (k == ' ') {
            while (p < line.end && (clean_[p] == ' ' || clean_[p] == '\t')) ++p;
            continue;
        }
        if (p >= line.end || lower(clean_[p]) != k) return false;
        ++p;
    }
    // A keyword ending in a letter must not run on into a name ("endlsystemx").
    if (is_letter(kw.back()) && p < line.end && is_name_char(clean_[p])) return false;
    after = p;
    return true;
}

void LParser::collect_defines()
{
    for (const Line& line : lines_) {
        std::size_t p = skip_blanks(line.begin, line.end);
        if (p >= line.end || clean_[p] != '#') continue;
        std::size_t q = skip_blanks(p + 1, line.end);
        std::size_t w = q;
        while (w < line.end && is_name_char(clean_[w])) ++w;
        const std::string_view directive = text().substr(q, w - q);
        if (directive != "define") continue;
        std::size_t n = skip_blanks(w, line.end);
        std::size_t ne = n;
        while (ne < line.end && is_name_char(clean_[ne])) ++ne;
        if (ne == n || !is_name_start(clean_[n])) src().fail(n, "#define needs a name");
        const std::string name(text().substr(n, ne - n));
        if (ne < line.end && clean_[ne] == '(') {
            warn(p, "function-like #define '" + name + "' is not supported; ignored");
            continue;
        }
        detail::Define d;
        d.name_offset = n;
        d.begin = skip_blanks(ne, line.end);
        d.end = trim_end(d.begin, line.end);
        if (d.begin == d.end) src().fail(n, "#define " + name + " has no value");
        if (defines_.count(name) != 0) warn(n, "#define " + name + " given again; the last one counts");
        defines_[name] = d;
    }
}

void LParser::skip_block(std::size_t& i, std::size_t from, const char* what)
{
    // From `from` on line i: a `{ … }` block, possibly over several lines.
    std::size_t p = skip_blanks(from, lines_[i].end);
    if (p >= lines_[i].end || clean_[p] != '{') {
        // `define:` without a block: nothing to skip.
        warn(from, std::string(what) + " without a '{' block; ignored");
        return;
    }
    warn(p, std::string(what) + " statement blocks '{…}' are not supported; the block is ignored");
    int depth = 0;
    for (std::size_t k = p; k < clean_.size(); ++k) {
        if (clean_[k] == '{') ++depth;
        else if (clean_[k] == '}' && --depth == 0) {
            while (i + 1 < lines_.size() && lines_[i].end < k) ++i;
            return;
        }
    }
    src().fail(p, "unclosed '{' block");
}

SymbolId LParser::intern(std::string_view name, std::size_t offset)
{
    const std::string key(name);
    const auto it = sys_->symbol_ids.find(key);
    if (it != sys_->symbol_ids.end()) return it->second;
    if (sys_->symbol_names.size() >= kMaxSymbols) src().fail(offset, "too many different modules");
    const auto id = static_cast<SymbolId>(sys_->symbol_names.size());
    sys_->symbol_names.push_back(key);
    sys_->symbol_ids.emplace(key, id);
    return id;
}

std::string_view LParser::read_symbol(std::size_t& p, std::size_t end)
{
    const char c = clean_[p];
    const auto uc = static_cast<unsigned char>(c);
    if (uc < 33 || uc > 126) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "0x%02X", uc);
        src().fail(p, std::string("byte ") + buf + " is not a module (modules are printable ASCII characters)");
    }
    switch (c) {
    case '<': case '>': case ':': src().fail(p, std::string("unexpected '") + c + "'");
    case '*': src().fail(p, "'*' is not a module ('*' stands alone for no context, no condition or an empty successor)");
    case '(': src().fail(p, "'(' without a module before it");
    case ')': src().fail(p, "unbalanced ')'");
    default: break;
    }
    const std::size_t start = p++;
    if ((c == '?' || c == '@') && p < end && is_letter(clean_[p])) {
        const char k = clean_[p++];
        // cpfg's three-character commands @Gs, @Ge, @Gc, @Gr, @Tx, @Ds, @Di, @Dd …
        if (c == '@' && (k == 'G' || k == 'D' || k == 'T') && p < end && clean_[p] >= 'a' && clean_[p] <= 'z') ++p;
    }
    return text().substr(start, p - start);
}

template <class Item>
void LParser::read_parameter_list(std::size_t& p, std::size_t end, const std::string& unclosed, const char* kind, Item&& item)
{
    const std::size_t q = skip_blanks(p, end);
    if (q >= end || clean_[q] != '(') return;
    p = skip_blanks(q + 1, end);
    if (p < end && clean_[p] == ')') {
        ++p;
        return;
    }
    for (;;) {
        item(p);
        if (p < end && clean_[p] == ',') {
            ++p;
            continue;
        }
        if (p < end && clean_[p] == ')') {
            ++p;
            return;
        }
        if (p >= end) src().fail(q, unclosed);
        src().fail(p, std::string("expected ',' or ')' after a ") + kind + ", found '" + std::string(text().substr(p, 1)) + "'");
    }
}

void LParser::parse_modules(std::size_t begin, std::size_t end, std::vector<SuccessorModule>& out,
                            std::vector<Expr>& exprs, const char* what)
{
    std::size_t p = skip_blanks(begin, end);
    while (p < end) {
        const std::size_t at = p;
        const std::string_view name = read_symbol(p, end);
        SuccessorModule m;
        m.symbol = intern(name, at);
        m.first_expr = static_cast<std::uint32_t>(exprs.size());
        read_parameter_list(p, end, std::string("unclosed '(' in the ") + what, "parameter", [&](std::size_t& at_p) {
            if (exprs.size() - m.first_expr >= kMaxModuleParams) src().fail(at, "a module with more than 255 parameters");
            exprs.push_back(compiler_->compile(at_p, end));
        });
        m.param_count = static_cast<std::uint16_t>(exprs.size() - m.first_expr);
        out.push_back(m);
        p = skip_blanks(p, end);
    }
}

void LParser::parse_pattern(std::size_t begin, std::size_t end, std::vector<PatternModule>& out,
                            std::unordered_map<std::string, std::uint32_t>& scope, std::vector<std::size_t>& offsets)
{
    std::size_t p = skip_blanks(begin, end);
    while (p < end) {
        const std::size_t at = p;
        const std::string_view name = read_symbol(p, end);
        PatternModule m;
        m.symbol = intern(name, at);
        m.first_var = static_cast<std::uint32_t>(scope.size());
        std::uint32_t count = 0;
        read_parameter_list(p, end, "unclosed '('", "parameter name", [&](std::size_t& at_p) {
            at_p = skip_blanks(at_p, end);
            std::size_t e = at_p;
            while (e < end && is_name_char(clean_[e])) ++e;
            if (e == at_p || !is_name_start(clean_[at_p]))
                src().fail(at_p, "expected a parameter name in '" + std::string(name) + "(…)' of a predecessor or context");
            const std::string formal(text().substr(at_p, e - at_p));
            if (scope.count(formal) != 0) src().fail(at_p, "parameter '" + formal + "' named twice in one production");
            if (scope.size() >= kMaxProductionVars) src().fail(at_p, "a production with more than 1024 parameters");
            if (++count > kMaxModuleParams) src().fail(at, "a module with more than 255 parameters");
            scope.emplace(formal, static_cast<std::uint32_t>(scope.size()));
            at_p = skip_blanks(e, end);
        });
        m.param_count = static_cast<std::uint16_t>(count);
        out.push_back(m);
        offsets.push_back(at);
        p = skip_blanks(p, end);
    }
}

void LParser::parse_symbol_list(std::size_t begin, std::size_t end, std::vector<SymbolId>& out)
{
    std::size_t p = skip_blanks(begin, end);
    while (p < end) {
        const std::size_t at = p;
        const std::string_view name = read_symbol(p, end);
        if (name == "[" || name == "]") {
            warn(at, "brackets always delimit branches when matching context; '" + std::string(name) +
                         "' in the list is ignored");
        } else {
            out.push_back(intern(name, at));
        }
        p = skip_blanks(p, end);
    }
}

void LParser::check_brackets(const std::vector<SuccessorModule>& modules, std::size_t offset, const char* what) const
{
    long depth = 0;
    for (const SuccessorModule& m : modules) {
        const std::string& n = sys_->symbol_names[m.symbol];
        if (n == "[") ++depth;
        if (n == "]" && --depth < 0) src().fail(offset, std::string("unbalanced brackets in the ") + what + ": a ']' closes no '['");
    }
    if (depth > 0) src().fail(offset, std::string("unbalanced brackets in the ") + what + ": " + std::to_string(depth) + " '[' left open");
}

double LParser::constant_value(std::size_t begin, std::size_t end, const char* what)
{
    compiler_->set_scope(nullptr);
    const std::size_t p = skip_blanks(begin, end);
    if (p >= trim_end(begin, end)) src().fail(begin, std::string(what) + " needs a value");
    const Expr e = compiler_->compile_all(p, trim_end(p, end));
    const double v = compiler_->evaluate_constant(e, p);
    if (!std::isfinite(v)) src().fail(p, std::string(what) + " is not a finite number");
    return v;
}

/// Finds `needle` at parenthesis and brace depth 0 in [begin, end); the first one, or npos.
std::size_t find_top_level(std::string_view text, std::size_t begin, std::size_t end, char needle)
{
    int paren = 0;
    int brace = 0;
    for (std::size_t i = begin; i < end; ++i) {
        const char c = text[i];
        if (c == '(') ++paren;
        else if (c == ')') paren = std::max(0, paren - 1);
        else if (c == '{') ++brace;
        else if (c == '}') brace = std::max(0, brace - 1);
        else if (c == needle && paren == 0 && brace == 0) return i;
    }
    return std::string_view::npos;
}

std::pair<std::size_t, std::size_t> LParser::find_arrow(std::size_t begin, std::size_t end) const
{
    // The last `->` at depth 0 (successors cannot hold '>'), `-->`, `->` or `-o>`.
    std::size_t arrow = std::string_view::npos;
    std::size_t arrow_end = 0;
    int paren = 0;
    int brace = 0;
    std::size_t open_paren = 0;
    for (std::size_t i = begin; i < end; ++i) {
        const char c = clean_[i];
        if (c == '(') {
            if (paren++ == 0) open_paren = i;
        } else if (c == ')') {
            if (paren == 0) src().fail(i, "unbalanced ')'");
            --paren;
        }
        else if (c == '{') ++brace;
        else if (c == '}') brace = std::max(0, brace - 1);
        else if (paren == 0 && brace == 0 && c == '-' && i + 1 < end && clean_[i + 1] == '>') {
            arrow = i;
            arrow_end = i + 2;
        } else if (paren == 0 && brace == 0 && c == '-' && clean_[i + 1] == 'o' && i + 2 < end && clean_[i + 2] == '>') {
            arrow = i;
            arrow_end = i + 3;
        }
    }
    if (paren > 0) src().fail(open_paren, "unclosed '('");
    if (arrow != std::string_view::npos && clean_[arrow + 1] == '>' && arrow > begin && clean_[arrow - 1] == '-') --arrow;
    return {arrow, arrow_end};
}

void LParser::parse_left_side(Production& prod, std::size_t begin, std::size_t ctx_end, Scope& scope)
{
    // lc < pred > rc
    const std::size_t lt = find_top_level(clean_, begin, ctx_end, '<');
    const std::size_t gt = find_top_level(clean_, lt == std::string_view::npos ? begin : lt + 1, ctx_end, '>');
    const std::size_t pred_begin = lt == std::string_view::npos ? begin : lt + 1;
    const std::size_t pred_end = gt == std::string_view::npos ? ctx_end : gt;
    if (lt != std::string_view::npos && find_top_level(clean_, lt + 1, ctx_end, '<') != std::string_view::npos)
        src().fail(find_top_level(clean_, lt + 1, ctx_end, '<'), "a production has one '<' at most");
    if (gt != std::string_view::npos && find_top_level(clean_, gt + 1, ctx_end, '>') != std::string_view::npos)
        src().fail(find_top_level(clean_, gt + 1, ctx_end, '>'), "a production has one '>' at most");

    std::vector<std::size_t> offsets;
    std::vector<PatternModule> pred;
    const std::size_t pb = skip_blanks(pred_begin, pred_end);
    if (pb >= pred_end) src().fail(pred_begin, "a production needs a predecessor");
    parse_pattern(pb, trim_end(pb, pred_end), pred, scope, offsets);
    if (pred.size() != 1)
        src().fail(offsets[1], "a predecessor is one module (cpfg's predecessors of several modules are not supported)");
    const std::string& pn = sys_->symbol_names[pred[0].symbol];
    if (pn == "[" || pn == "]") src().fail(pb, "brackets cannot be rewritten");
    prod.pred = pred[0];

    auto context = [&](std::size_t b, std::size_t e, std::vector<PatternModule>& out, bool is_left) {
        const std::size_t cb = skip_blanks(b, e);
        const std::size_t ce = trim_end(cb, e);
        if (cb >= ce) src().fail(b, is_left ? "an empty left context (write '*' for none)" : "an empty right context (write '*' for none)");
        if (ce == cb + 1 && clean_[cb] == '*') return;
        std::vector<std::size_t> offs;
        parse_pattern(cb, ce, out, scope, offs);
        for (std::size_t k = 0; k < out.size(); ++k) {
            const std::string& n = sys_->symbol_names[out[k].symbol];
            if (is_left && (n == "[" || n == "]")) src().fail(offs[k], "a left context cannot hold brackets");
        }
    };
    if (lt != std::string_view::npos) context(begin, lt, prod.left, true);
    if (gt != std::string_view::npos) context(gt + 1, ctx_end, prod.right, false);
}

void LParser::parse_condition(Production& prod, std::size_t colon, std::size_t arrow)
{
    std::size_t cb = skip_blanks(colon + 1, arrow);
    std::size_t ce = trim_end(cb, arrow);
    // cpfg's pre- and post-condition statement blocks: `{ … } cond { … }`.
    if (cb < ce && clean_[cb] == '{') {
        std::size_t depth = 0;
        std::size_t k = cb;
        for (; k < ce; ++k) {
            if (clean_[k] == '{') ++depth;
            else if (clean_[k] == '}' && --depth == 0) break;
        }
        if (k >= ce) src().fail(cb, "unclosed '{' block");
        warn(cb, "statement blocks '{…}' before a condition are not supported; the block is ignored");
        cb = skip_blanks(k + 1, ce);
    }
    if (cb < ce && clean_[ce - 1] == '}') {
        std::size_t depth = 0;
        std::size_t k = ce;
        while (k > cb) {
            --k;
            if (clean_[k] == '}') ++depth;
            else if (clean_[k] == '{' && --depth == 0) break;
        }
        if (clean_[k] != '{' || depth != 0) src().fail(ce - 1, "unbalanced '}'");
        warn(k, "statement blocks '{…}' after a condition are not supported; the block is ignored");
        ce = trim_end(cb, k);
    }
    if (cb >= ce) src().fail(colon, "an empty condition (write '*' for none)");
    if (!(ce == cb + 1 && clean_[cb] == '*')) {
        prod.condition = compiler_->compile_all(cb, ce);
        prod.has_condition = !(prod.condition.constant && prod.condition.value != 0.0);
    }
}

void LParser::parse_right_side(Production& prod, std::size_t arrow_end, std::size_t end)
{
    // succ : prob
    const std::size_t prob_colon = find_top_level(clean_, arrow_end, end, ':');
    const std::size_t succ_end = prob_colon == std::string_view::npos ? end : prob_colon;
    const std::size_t sb = skip_blanks(arrow_end, succ_end);
    const std::size_t se = trim_end(sb, succ_end);
    if (sb >= se) src().fail(arrow_end, "an empty successor (write '*' for the empty word)");
    if (!(se == sb + 1 && clean_[sb] == '*')) {
        parse_modules(sb, se, prod.successor, prod.param_exprs, "successor");
        check_brackets(prod.successor, sb, "successor");
    }
    if (prob_colon != std::string_view::npos) {
        const std::size_t pb = skip_blanks(prob_colon + 1, end);
        const std::size_t pe = trim_end(pb, end);
        if (pb >= pe) src().fail(prob_colon, "a ':' after the successor needs a probability");
        prod.probability = compiler_->compile_all(pb, pe);
        prod.has_probability = true;
        if (prod.probability.constant && !(prod.probability.value >= 0.0 && std::isfinite(prod.probability.value)))
            src().fail(pb, "a probability must be a finite number of at least 0, not " + number_text(prod.probability.value));
    }
}

/// A successor whose parameters are all constant becomes a block copied as it is.
void prebuild_constant_successor(Production& prod)
{
    for (const Expr& e : prod.param_exprs)
        if (!e.constant) {
            prod.constant_successor = false;
            prod.successor_cost += e.count;
        }
    prod.successor_param_count = static_cast<std::uint32_t>(prod.param_exprs.size());
    if (!prod.constant_successor) return;
    for (const SuccessorModule& s : prod.successor) {
        Module m;
        m.symbol = s.symbol;
        m.param_count = s.param_count;
        m.first_param = static_cast<std::uint32_t>(prod.block_params.size());
        for (std::uint32_t k = 0; k < s.param_count; ++k) prod.block_params.push_back(prod.param_exprs[s.first_expr + k].value);
        prod.block.push_back(m);
    }
}

void LParser::parse_production(std::size_t begin, std::size_t end)
{
    const auto [arrow, arrow_end] = find_arrow(begin, end);
    const std::size_t first = skip_blanks(begin, end);
    if (arrow == std::string_view::npos)
        src().fail(first, "not a production (no '-->') nor a statement cpfg knows: '" +
                              shorten(text().substr(first, trim_end(first, end) - first)) + "'");
    if (clean_.compare(arrow, 3, "-o>") == 0) warn(arrow, "'-o>' (object productions) read as '-->'");

    Production prod;
    prod.offset = first;
    const auto [line, col] = src().line_col(first);
    prod.where = name_ + ":" + std::to_string(line) + ":" + std::to_string(col);
    // lc < pred > rc : cond --> succ : prob
    const std::size_t colon = find_top_level(clean_, begin, arrow, ':');
    const std::size_t ctx_end = colon == std::string_view::npos ? arrow : colon;
    Scope scope;
    parse_left_side(prod, begin, ctx_end, scope);
    prod.var_count = static_cast<std::uint32_t>(scope.size());
    compiler_->set_scope(&scope);
    if (colon != std::string_view::npos) parse_condition(prod, colon, arrow);
    parse_right_side(prod, arrow_end, end);
    compiler_->set_scope(nullptr);
    prebuild_constant_successor(prod);

    if (section_ != &sys_->main && prod.is_context_sensitive()) {
        warn(first, std::string("context in a ") + (section_ == &sys_->homomorphism ? "homomorphism" : "decomposition") +
                        " production is ignored (it is matched as context-free)");
        prod.left.clear();
        prod.right.clear();
    }
    if (prod.has_probability) {
        // Productions of one predecessor, context and condition form a group whose weights
        // should add up to 1 (checked once all are read).
        const std::string key = std::to_string(reinterpret_cast<std::uintptr_t>(section_)) + "|" +
                                std::string(text().substr(begin, ctx_end - begin)) + "|" +
                                (colon == std::string_view::npos ? std::string() : std::string(text().substr(colon, arrow - colon)));
        std::string k;
        for (const char c : key)
            if (!is_blank(c)) k += c;
        groups_.push_back({k, prod.probability.constant ? prod.probability.value : 0.0, first, prod.probability.constant});
    }
    section_->max_vars = std::max(section_->max_vars, prod.var_count);
    if (prod.is_context_sensitive()) section_->has_context = true;
    section_->productions.push_back(std::move(prod));
}

void LParser::finish_probability_groups()
{
    std::vector<bool> done(groups_.size(), false);
    for (std::size_t i = 0; i < groups_.size(); ++i) {
        if (done[i]) continue;
        double sum = 0.0;
        bool constant = true;
        for (std::size_t j = i; j < groups_.size(); ++j) {
            if (groups_[j].key != groups_[i].key) continue;
            done[j] = true;
            sum += groups_[j].probability;
            constant = constant && groups_[j].constant;
        }
        if (constant && std::fabs(sum - 1.0) > 1e-6)
            warn(groups_[i].offset, "the probabilities of this predecessor's productions add up to " + number_text(sum) +
                                        ", not 1; they are normalised (as cpfg does)");
    }
}

void LParser::prepare()
{
    if (original_.size() > kMaxFileBytes)
        raw_.fail(0, "the file is " + std::to_string(original_.size()) + " bytes, over the limit of " +
                         std::to_string(kMaxFileBytes) + " bytes");
    clean_ = detail::blank_comments(original_, raw_);
    src_ = std::make_unique<SourceText>(clean_, name_);
    compiler_ = std::make_unique<detail::ExprCompiler>(
        *src_, sys_->code, defines_, [this](std::size_t off, const std::string& msg) { warn(off, msg); });
    sys_->source_name = name_;
    split_lines();
    collect_defines();
    // Every #define must be a valid expression (unused ones too: a recursion or a constant
    // division by zero is an error wherever it is).
    std::vector<std::pair<std::size_t, std::string>> order;
    for (const auto& [n, d] : defines_) order.emplace_back(d.name_offset, n);
    std::sort(order.begin(), order.end());
    for (const auto& [off, n] : order) compiler_->check_define(n);
    section_ = &sys_->main;
}

void LParser::read_line(std::size_t& i)
{
    const Line line = lines_[i];
    const std::size_t p = skip_blanks(line.begin, line.end);
    if (p >= line.end) return;
    state_.last_offset = p;
    std::size_t after = 0;
    if (clean_[p] == '#') {
        std::size_t q = skip_blanks(p + 1, line.end);
        std::size_t w = q;
        while (w < line.end && is_name_char(clean_[w])) ++w;
        const std::string_view directive = text().substr(q, w - q);
        if (directive != "define") warn(p, "preprocessor line '#" + shorten(directive) + "' is not supported; ignored");
        return;
    }
    if (state_.ended) {
        if (keyword(line, "lsystem:", after)) {
            warn(p, "a second L-system in one file (cpfg's sub-L-systems) is not supported; ignored up to its endlsystem");
            while (i + 1 < lines_.size()) {
                ++i;
                if (keyword(lines_[i], "endlsystem", after)) break;
            }
            return;
        }
        if (!state_.warned_after_end) warn(p, "text after 'endlsystem' is ignored");
        state_.warned_after_end = true;
        return;
    }
    if (!state_.seen_header) {
        if (!keyword(line, "lsystem:", after))
            src().fail(p, "expected 'Lsystem: NAME' before anything else, found '" +
                              shorten(text().substr(p, trim_end(p, line.end) - p)) + "'");
        state_.seen_header = true;
        return;
    }
    if (read_statement(i, p)) return;
    parse_production(p, production_end(i, p));
}

bool LParser::read_statement(std::size_t& i, std::size_t p)
{
    const Line line = lines_[i];
    std::size_t after = 0;
    if (keyword(line, "lsystem:", after)) src().fail(p, "'Lsystem:' again before 'endlsystem'");
    if (keyword(line, "endlsystem", after)) {
        state_.ended = true;
    } else if (keyword(line, "derivation length:", after)) {
        const double v = constant_value(after, line.end, "derivation length");
        if (v < 0.0 || v > static_cast<double>(kMaxDerivationLength))
            src().fail(skip_blanks(after, line.end), "derivation length " + number_text(v) + " is outside 0 to " +
                                                         std::to_string(kMaxDerivationLength));
        sys_->derivation_length = static_cast<int>(v);
    } else if (keyword(line, "maximum depth:", after)) {
        const double v = constant_value(after, line.end, "maximum depth");
        if (v < 0.0 || v > kMaxSectionDepth)
            src().fail(skip_blanks(after, line.end), "maximum depth " + number_text(v) + " is outside 0 to " +
                                                         std::to_string(kMaxSectionDepth));
        if (section_ == &sys_->main) warn(p, "'maximum depth:' outside a decomposition or homomorphism section is ignored");
        else section_->depth = static_cast<int>(v);
    } else if (keyword(line, "seed:", after)) {
        warn(p, "'seed:' is not used: the seed comes from the caller (--seed)");
    } else if (keyword(line, "ignore:", after)) {
        state_.ignore_list.clear();
        parse_symbol_list(after, line.end, state_.ignore_list);
        if (state_.context_list == 2) warn(p, "'ignore:' after 'consider:': the last one counts");
        state_.context_list = 1;
    } else if (keyword(line, "consider:", after)) {
        state_.consider_list.clear();
        parse_symbol_list(after, line.end, state_.consider_list);
        if (state_.context_list == 1) warn(p, "'consider:' after 'ignore:': the last one counts");
        state_.context_list = 2;
    } else if (keyword(line, "axiom:", after)) {
        parse_axiom(p, after, line.end);
    } else if (keyword(line, "ring lsystem", after)) {
        warn(p, "ring L-systems are not supported; the word is read as an ordinary one");
    } else if (keyword(line, "homomorphism", after) || keyword(line, "decomposition", after)) {
        start_section(p, after, line.end);
    } else {
        for (const char* kw : {"define:", "start each:", "end each:", "start:", "end:"}) {
            if (keyword(line, kw, after)) {
                skip_block(i, after, kw);
                return true;
            }
        }
        return false;
    }
    return true;
}

void LParser::parse_axiom(std::size_t p, std::size_t after, std::size_t line_end)
{
    if (state_.seen_axiom) src().fail(p, "a second 'Axiom:'");
    state_.seen_axiom = true;
    compiler_->set_scope(nullptr);
    std::vector<SuccessorModule> mods;
    std::vector<Expr> exprs;
    const std::size_t b = skip_blanks(after, line_end);
    const std::size_t e = trim_end(b, line_end);
    if (b >= e) src().fail(after, "an empty axiom");
    parse_modules(b, e, mods, exprs, "axiom");
    check_brackets(mods, b, "axiom");
    if (mods.size() > kMaxModules) src().fail(b, "the axiom is over the module limit");
    for (const SuccessorModule& m : mods) {
        std::vector<double> values;
        for (std::uint32_t k = 0; k < m.param_count; ++k) {
            const Expr& ex = exprs[m.first_expr + k];
            const double v = compiler_->evaluate_constant(ex, ex.offset);
            if (!std::isfinite(v)) src().fail(ex.offset, "a parameter of the axiom is not a finite number");
            values.push_back(v);
        }
        sys_->axiom.push(m.symbol, values);
    }
}

void LParser::start_section(std::size_t p, std::size_t after, std::size_t line_end)
{
    const bool homo = lower(clean_[p]) == 'h';
    std::size_t q = skip_blanks(after, line_end);
    if (q < line_end && clean_[q] == ':') q = skip_blanks(q + 1, line_end);
    const std::string_view rest = text().substr(q, trim_end(q, line_end) - q);
    if (!rest.empty() && rest != "warnings" && rest != "no warnings")
        src().fail(q, std::string("unexpected '") + shorten(rest) + "' after '" + (homo ? "homomorphism" : "decomposition") + "'");
    ProductionSet* next = homo ? &sys_->homomorphism : &sys_->decomposition;
    if (next == section_ || (section_ == &sys_->homomorphism && !homo))
        src().fail(p, homo ? "a second 'homomorphism' section" : "'decomposition' comes before 'homomorphism', once");
    section_ = next;
}

std::size_t LParser::production_end(std::size_t& i, std::size_t p) const
{
    // A production goes on over the following lines while a '{' block before its arrow is open.
    std::size_t end = lines_[i].end;
    int depth = 0;
    for (std::size_t k = p; k < end; ++k) {
        if (clean_[k] == '{') ++depth;
        else if (clean_[k] == '}') --depth;
    }
    bool has_arrow = text().substr(p, end - p).find("->") != std::string_view::npos ||
                     text().substr(p, end - p).find("-o>") != std::string_view::npos;
    while (depth > 0 && !has_arrow && i + 1 < lines_.size()) {
        ++i;
        for (std::size_t k = lines_[i].begin; k < lines_[i].end; ++k) {
            if (clean_[k] == '{') ++depth;
            else if (clean_[k] == '}') --depth;
        }
        end = lines_[i].end;
        has_arrow = text().substr(lines_[i].begin, end - lines_[i].begin).find("->") != std::string_view::npos;
    }
    return end;
}

void LParser::finish()
{
    if (!state_.seen_header) raw_.fail(0, "not an L-system: no 'Lsystem:' line");
    if (!state_.seen_axiom) src().fail(state_.last_offset, "no 'Axiom:'");
    if (!state_.ended) warn(state_.last_offset, "no 'endlsystem' at the end");
    finish_probability_groups();

    // Context: ignore/consider lists over every symbol.
    const std::size_t n = sys_->symbol_names.size();
    sys_->ignored.assign(n, 0);
    if (state_.context_list == 1) {
        for (const SymbolId s : state_.ignore_list) sys_->ignored[s] = 1;
    } else if (state_.context_list == 2) {
        sys_->ignored.assign(n, 1);
        for (const SymbolId s : state_.consider_list) sys_->ignored[s] = 0;
    }
    auto find = [&](const char* s) {
        const auto it = sys_->symbol_ids.find(s);
        return it == sys_->symbol_ids.end() ? kNoSymbol : it->second;
    };
    sys_->left_bracket = find("[");
    sys_->right_bracket = find("]");
    sys_->cut = find("%");
    if (sys_->left_bracket != kNoSymbol) sys_->ignored[sys_->left_bracket] = 0;
    if (sys_->right_bracket != kNoSymbol) sys_->ignored[sys_->right_bracket] = 0;
    for (const char* q : {"?P", "?H", "?L", "?U", "?E"}) {
        const SymbolId s = find(q);
        if (s == kNoSymbol) continue;
        auto uses = [&](const ProductionSet& set) {
            for (const Production& pr : set.productions)
                for (const SuccessorModule& m : pr.successor)
                    if (m.symbol == s) return true;
            return false;
        };
        bool in_axiom = false;
        for (const Module& m : sys_->axiom.modules)
            if (m.symbol == s) in_axiom = true;
        if (in_axiom || uses(sys_->main) || uses(sys_->decomposition)) sys_->has_queries = true;
    }
    detail::index_productions(sys_->main, n);
    detail::index_productions(sys_->decomposition, n);
    detail::index_productions(sys_->homomorphism, n);
    warnings_.finish(name_);
}

std::shared_ptr<const LSystem::Impl> LParser::run()
{
    prepare();
    for (std::size_t i = 0; i < lines_.size(); ++i) read_line(i);
    finish();
    return sys_;
}

} // namespace

LSystem parse_lsystem(std::string_view text, const std::string& source_name, std::vector<std::string>* warnings)
{
    LParser parser(text, source_name, warnings);
    return LSystem(parser.run());
}

} // namespace lobe::lsystem
