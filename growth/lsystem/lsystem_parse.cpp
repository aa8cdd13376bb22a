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

namespace lobe::lsystem {

namespace {

using detail::Expr;
using detail::PatternModule;
using detail::Production;
using detail::ProductionSet;
using detail::SourceText;
using detail::SuccessorModule;

/// Most warning lines one file gives; past it, one line says how many more there were.
constexpr std::size_t kMaxWarnings = 200;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_name_char(char c) { return is_name_start(c) || (c >= '0' && c <= '9'); }
bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

std::string shorten(std::string_view s)
{
    std::string out(s.substr(0, std::min<std::size_t>(s.size(), 60)));
    if (s.size() > 60) out += "…";
    return out;
}

std::string number_text(double v)
{
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

/// Collects warnings, one line each, capped.
class Warnings {
public:
    explicit Warnings(std::vector<std::string>* out) : out_(out) {}
    void add(std::string line)
    {
        if (out_ == nullptr) return;
        ++count_;
        if (count_ <= kMaxWarnings) out_->push_back(one_line_message(line));
    }
    void finish(const std::string& name)
    {
        if (out_ != nullptr && count_ > kMaxWarnings)
            out_->push_back(name + ": " + std::to_string(count_ - kMaxWarnings) + " more warnings not shown");
    }

private:
    std::vector<std::string>* out_;
    std::size_t count_ = 0;
};

/// Blanks comments (keeping newlines, so positions stay): `/* … */` anywhere, and `//` to the
/// end of the line where it starts a line or stands between blanks (`F // note`); elsewhere
/// `//` is two turtle rolls (`F//F`, ABOP's `/////`).
std::string blank_comments(std::string_view text, const SourceText& src)
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

/// The parser of one `.l` file.
class LParser {
public:
    LParser(std::string_view text, const std::string& name, std::vector<std::string>* warnings)
        : original_(text), name_(name), warnings_(warnings), raw_(text, name)
    {
    }

    std::shared_ptr<const LSystem::Impl> run();

private:
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

    void split_lines();
    void collect_defines();
    /// Whether line `i` starts with `keyword` (letters case-insensitive, blanks within the
    /// keyword optional); sets `after` to the offset after it.
    bool keyword(const Line& line, std::string_view keyword, std::size_t& after) const;
    void skip_block(std::size_t& i, std::size_t from, const char* what);

    SymbolId intern(std::string_view name, std::size_t offset);
    /// Reads one module name at `p` (a character, `?X`, `@X`); moves `p` past it.
    std::string_view read_symbol(std::size_t& p, std::size_t end);
    /// Modules with parameter expressions (axiom, successor). Appends to `out`.
    void parse_modules(std::size_t begin, std::size_t end, std::vector<SuccessorModule>& out,
                       std::vector<Expr>& exprs, const char* what);
    /// Modules with formal parameters (predecessor, contexts).
    void parse_pattern(std::size_t begin, std::size_t end, std::vector<PatternModule>& out,
                       std::unordered_map<std::string, std::uint32_t>& scope, std::vector<std::size_t>& offsets);
    void parse_symbol_list(std::size_t begin, std::size_t end, std::vector<SymbolId>& out);
    void parse_production(std::size_t begin, std::size_t end);
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
    std::vector<std::size_t> production_group_offsets_;
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
        std::size_t q = skip_blanks(p, end);
        if (q < end && clean_[q] == '(') {
            p = skip_blanks(q + 1, end);
            if (p < end && clean_[p] == ')') {
                ++p;
            } else {
                for (;;) {
                    if (exprs.size() - m.first_expr >= kMaxModuleParams)
                        src().fail(at, "a module with more than 255 parameters");
                    exprs.push_back(compiler_->compile(p, end));
                    if (p < end && clean_[p] == ',') {
                        ++p;
                        continue;
                    }
                    if (p < end && clean_[p] == ')') {
                        ++p;
                        break;
                    }
                    if (p >= end) src().fail(q, std::string("unclosed '(' in the ") + what);
                    src().fail(p, "expected ',' or ')' after a parameter, found '" + std::string(text().substr(p, 1)) + "'");
                }
            }
        }
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
        std::size_t q = skip_blanks(p, end);
        std::uint32_t count = 0;
        if (q < end && clean_[q] == '(') {
            p = skip_blanks(q + 1, end);
            if (p < end && clean_[p] == ')') {
                ++p;
            } else {
                for (;;) {
                    p = skip_blanks(p, end);
                    std::size_t e = p;
                    while (e < end && is_name_char(clean_[e])) ++e;
                    if (e == p || !is_name_start(clean_[p]))
                        src().fail(p, "expected a parameter name in '" + std::string(name) + "(…)' of a predecessor or context");
                    const std::string formal(text().substr(p, e - p));
                    if (scope.count(formal) != 0) src().fail(p, "parameter '" + formal + "' named twice in one production");
                    if (scope.size() >= kMaxProductionVars) src().fail(p, "a production with more than 1024 parameters");
                    if (++count > kMaxModuleParams) src().fail(at, "a module with more than 255 parameters");
                    scope.emplace(formal, static_cast<std::uint32_t>(scope.size()));
                    p = skip_blanks(e, end);
                    if (p < end && clean_[p] == ',') {
                        ++p;
                        continue;
                    }
                    if (p < end && clean_[p] == ')') {
                        ++p;
                        break;
                    }
                    if (p >= end) src().fail(q, "unclosed '('");
                    src().fail(p, "expected ',' or ')' after a parameter name, found '" + std::string(text().substr(p, 1)) + "'");
                }
            }
        }
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

void LParser::parse_production(std::size_t begin, std::size_t end)
{
    // The arrow: the last `->` at depth 0 (successors cannot hold '>'), `-->`, `->` or `-o>`.
    std::size_t arrow = std::string_view::npos;
    std::size_t arrow_end = 0;
    {
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
    }
    const std::size_t first = skip_blanks(begin, end);
    if (arrow == std::string_view::npos)
        src().fail(first, "not a production (no '-->') nor a statement cpfg knows: '" +
                              shorten(text().substr(first, trim_end(first, end) - first)) + "'");
    if (clean_.compare(arrow, 3, "-o>") == 0) warn(arrow, "'-o>' (object productions) read as '-->'");

    Production prod;
    prod.offset = first;
    {
        const auto [line, col] = src().line_col(first);
        prod.where = name_ + ":" + std::to_string(line) + ":" + std::to_string(col);
    }
    // Left side: lc < pred > rc : cond
    const std::size_t colon = find_top_level(clean_, begin, arrow, ':');
    const std::size_t ctx_end = colon == std::string_view::npos ? arrow : colon;
    const std::size_t lt = find_top_level(clean_, begin, ctx_end, '<');
    const std::size_t gt = find_top_level(clean_, lt == std::string_view::npos ? begin : lt + 1, ctx_end, '>');
    const std::size_t pred_begin = lt == std::string_view::npos ? begin : lt + 1;
    const std::size_t pred_end = gt == std::string_view::npos ? ctx_end : gt;
    if (lt != std::string_view::npos && find_top_level(clean_, lt + 1, ctx_end, '<') != std::string_view::npos)
        src().fail(find_top_level(clean_, lt + 1, ctx_end, '<'), "a production has one '<' at most");
    if (gt != std::string_view::npos && find_top_level(clean_, gt + 1, ctx_end, '>') != std::string_view::npos)
        src().fail(find_top_level(clean_, gt + 1, ctx_end, '>'), "a production has one '>' at most");

    std::unordered_map<std::string, std::uint32_t> scope;
    std::vector<std::size_t> offsets;
    std::vector<PatternModule> pred;
    {
        const std::size_t pb = skip_blanks(pred_begin, pred_end);
        if (pb >= pred_end) src().fail(pred_begin, "a production needs a predecessor");
        parse_pattern(pb, trim_end(pb, pred_end), pred, scope, offsets);
        if (pred.size() != 1)
            src().fail(offsets[1], "a predecessor is one module (cpfg's predecessors of several modules are not supported)");
        const std::string& pn = sys_->symbol_names[pred[0].symbol];
        if (pn == "[" || pn == "]") src().fail(pb, "brackets cannot be rewritten");
        prod.pred = pred[0];
    }
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
    prod.var_count = static_cast<std::uint32_t>(scope.size());
    compiler_->set_scope(&scope);

    if (colon != std::string_view::npos) {
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

    // Right side: succ : prob
    const std::size_t prob_colon = find_top_level(clean_, arrow_end, end, ':');
    const std::size_t succ_end = prob_colon == std::string_view::npos ? end : prob_colon;
    {
        const std::size_t sb = skip_blanks(arrow_end, succ_end);
        const std::size_t se = trim_end(sb, succ_end);
        if (sb >= se) src().fail(arrow_end, "an empty successor (write '*' for the empty word)");
        if (!(se == sb + 1 && clean_[sb] == '*')) {
            parse_modules(sb, se, prod.successor, prod.param_exprs, "successor");
            check_brackets(prod.successor, sb, "successor");
        }
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
    compiler_->set_scope(nullptr);

    // Pre-build a constant successor.
    for (const Expr& e : prod.param_exprs)
        if (!e.constant) {
            prod.constant_successor = false;
            prod.successor_cost += e.count;
        }
    prod.successor_param_count = static_cast<std::uint32_t>(prod.param_exprs.size());
    if (prod.constant_successor) {
        for (const SuccessorModule& s : prod.successor) {
            Module m;
            m.symbol = s.symbol;
            m.param_count = s.param_count;
            m.first_param = static_cast<std::uint32_t>(prod.block_params.size());
            for (std::uint32_t k = 0; k < s.param_count; ++k) prod.block_params.push_back(prod.param_exprs[s.first_expr + k].value);
            prod.block.push_back(m);
        }
    }

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

std::shared_ptr<const LSystem::Impl> LParser::run()
{
    if (original_.size() > kMaxFileBytes)
        raw_.fail(0, "the file is " + std::to_string(original_.size()) + " bytes, over the limit of " +
                         std::to_string(kMaxFileBytes) + " bytes");
    clean_ = blank_comments(original_, raw_);
    src_ = std::make_unique<SourceText>(clean_, name_);
    compiler_ = std::make_unique<detail::ExprCompiler>(
        *src_, sys_->code, defines_, [this](std::size_t off, const std::string& msg) { warn(off, msg); });
    sys_->source_name = name_;
    split_lines();
    collect_defines();
    // Every #define must be a valid expression (unused ones too: a recursion or a constant
    // division by zero is an error wherever it is).
    {
        std::vector<std::pair<std::size_t, std::string>> order;
        for (const auto& [n, d] : defines_) order.emplace_back(d.name_offset, n);
        std::sort(order.begin(), order.end());
        for (const auto& [off, n] : order) compiler_->check_define(n);
    }

    section_ = &sys_->main;
    bool seen_header = false;
    bool seen_axiom = false;
    bool ended = false;
    bool warned_after_end = false;
    std::vector<SymbolId> ignore_list;
    std::vector<SymbolId> consider_list;
    int context_list = 0; // 0 none, 1 ignore, 2 consider
    std::size_t last_offset = 0;

    for (std::size_t i = 0; i < lines_.size(); ++i) {
        const Line line = lines_[i];
        const std::size_t p = skip_blanks(line.begin, line.end);
        if (p >= line.end) continue;
        last_offset = p;
        std::size_t after = 0;
        if (clean_[p] == '#') {
            std::size_t q = skip_blanks(p + 1, line.end);
            std::size_t w = q;
            while (w < line.end && is_name_char(clean_[w])) ++w;
            const std::string_view directive = text().substr(q, w - q);
            if (directive != "define")
                warn(p, "preprocessor line '#" + shorten(directive) + "' is not supported; ignored");
            continue;
        }
        if (ended) {
            if (keyword(line, "lsystem:", after)) {
                warn(p, "a second L-system in one file (cpfg's sub-L-systems) is not supported; ignored up to its endlsystem");
                while (i + 1 < lines_.size()) {
                    ++i;
                    if (keyword(lines_[i], "endlsystem", after)) break;
                }
                continue;
            }
            if (!warned_after_end) warn(p, "text after 'endlsystem' is ignored");
            warned_after_end = true;
            continue;
        }
        if (!seen_header) {
            if (!keyword(line, "lsystem:", after))
                src().fail(p, "expected 'Lsystem: NAME' before anything else, found '" +
                                  shorten(text().substr(p, trim_end(p, line.end) - p)) + "'");
            seen_header = true;
            continue;
        }
        if (keyword(line, "lsystem:", after)) src().fail(p, "'Lsystem:' again before 'endlsystem'");
        if (keyword(line, "endlsystem", after)) {
            ended = true;
            continue;
        }
        if (keyword(line, "derivation length:", after)) {
            const double v = constant_value(after, line.end, "derivation length");
            if (v < 0.0 || v > static_cast<double>(kMaxDerivationLength))
                src().fail(skip_blanks(after, line.end), "derivation length " + number_text(v) + " is outside 0 to " +
                                                             std::to_string(kMaxDerivationLength));
            sys_->derivation_length = static_cast<int>(v);
            continue;
        }
        if (keyword(line, "maximum depth:", after)) {
            const double v = constant_value(after, line.end, "maximum depth");
            if (v < 0.0 || v > kMaxSectionDepth)
                src().fail(skip_blanks(after, line.end), "maximum depth " + number_text(v) + " is outside 0 to " +
                                                             std::to_string(kMaxSectionDepth));
            if (section_ == &sys_->main) warn(p, "'maximum depth:' outside a decomposition or homomorphism section is ignored");
            else section_->depth = static_cast<int>(v);
            continue;
        }
        if (keyword(line, "seed:", after)) {
            warn(p, "'seed:' is not used: the seed comes from the caller (--seed)");
            continue;
        }
        if (keyword(line, "ignore:", after)) {
            ignore_list.clear();
            parse_symbol_list(after, line.end, ignore_list);
            if (context_list == 2) warn(p, "'ignore:' after 'consider:': the last one counts");
            context_list = 1;
            continue;
        }
        if (keyword(line, "consider:", after)) {
            consider_list.clear();
            parse_symbol_list(after, line.end, consider_list);
            if (context_list == 1) warn(p, "'consider:' after 'ignore:': the last one counts");
            context_list = 2;
            continue;
        }
        if (keyword(line, "axiom:", after)) {
            if (seen_axiom) src().fail(p, "a second 'Axiom:'");
            seen_axiom = true;
            compiler_->set_scope(nullptr);
            std::vector<SuccessorModule> mods;
            std::vector<Expr> exprs;
            const std::size_t b = skip_blanks(after, line.end);
            const std::size_t e = trim_end(b, line.end);
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
            continue;
        }
        bool block = false;
        for (const char* kw : {"define:", "start each:", "end each:", "start:", "end:"}) {
            if (keyword(line, kw, after)) {
                skip_block(i, after, kw);
                block = true;
                break;
            }
        }
        if (block) continue;
        if (keyword(line, "ring lsystem", after)) {
            warn(p, "ring L-systems are not supported; the word is read as an ordinary one");
            continue;
        }
        if (keyword(line, "homomorphism", after) || keyword(line, "decomposition", after)) {
            const bool homo = lower(clean_[p]) == 'h';
            std::size_t q = skip_blanks(after, line.end);
            if (q < line.end && clean_[q] == ':') q = skip_blanks(q + 1, line.end);
            const std::string_view rest = text().substr(q, trim_end(q, line.end) - q);
            if (!rest.empty() && rest != "warnings" && rest != "no warnings")
                src().fail(q, std::string("unexpected '") + shorten(rest) + "' after '" + (homo ? "homomorphism" : "decomposition") + "'");
            ProductionSet* next = homo ? &sys_->homomorphism : &sys_->decomposition;
            if (next == section_ || (section_ == &sys_->homomorphism && !homo))
                src().fail(p, homo ? "a second 'homomorphism' section" : "'decomposition' comes before 'homomorphism', once");
            section_ = next;
            continue;
        }
        // A production, possibly continued over lines while a '{' block before its arrow is open.
        std::size_t end = line.end;
        {
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
        }
        parse_production(p, end);
    }
    if (!seen_header) raw_.fail(0, "not an L-system: no 'Lsystem:' line");
    if (!seen_axiom) src().fail(last_offset, "no 'Axiom:'");
    if (!ended) warn(last_offset, "no 'endlsystem' at the end");
    finish_probability_groups();

    // Context: ignore/consider lists over every symbol.
    const std::size_t n = sys_->symbol_names.size();
    sys_->ignored.assign(n, 0);
    if (context_list == 1) {
        for (const SymbolId s : ignore_list) sys_->ignored[s] = 1;
    } else if (context_list == 2) {
        sys_->ignored.assign(n, 1);
        for (const SymbolId s : consider_list) sys_->ignored[s] = 0;
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
    return sys_;
}

// ---------------------------------------------------------------------------------------------
// View files

bool parse_numbers(std::string_view s, std::vector<double>& out)
{
    std::size_t p = 0;
    while (p < s.size()) {
        while (p < s.size() && (is_blank(s[p]) || s[p] == ',')) ++p;
        if (p >= s.size()) break;
        double v = 0.0;
        const char* b = s.data() + p;
        if (*b == '+') ++b;
        const auto r = std::from_chars(b, s.data() + s.size(), v);
        if (r.ec != std::errc() || !std::isfinite(v)) return false;
        out.push_back(v);
        p = static_cast<std::size_t>(r.ptr - s.data());
        if (p < s.size() && !is_blank(s[p]) && s[p] != ',') return false;
    }
    return true;
}

} // namespace

LSystem parse_lsystem(std::string_view text, const std::string& source_name, std::vector<std::string>* warnings)
{
    LParser parser(text, source_name, warnings);
    return LSystem(parser.run());
}

ViewSettings parse_view(std::string_view text, const std::string& source_name, std::vector<std::string>* warnings)
{
    SourceText raw(text, source_name);
    if (text.size() > kMaxFileBytes)
        raw.fail(0, "the file is " + std::to_string(text.size()) + " bytes, over the limit of " + std::to_string(kMaxFileBytes) + " bytes");
    const std::string clean = blank_comments(text, raw);
    const SourceText src(clean, source_name);
    Warnings warn(warnings);
    ViewSettings v;
    std::size_t b = 0;
    while (b <= clean.size()) {
        std::size_t e = clean.find('\n', b);
        if (e == std::string::npos) e = clean.size();
        std::size_t p = b;
        while (p < e && is_blank(clean[p])) ++p;
        std::size_t end = e;
        while (end > p && is_blank(clean[end - 1])) --end;
        if (p < end) {
            const std::size_t colon = clean.find(':', p);
            std::string label;
            if (colon != std::string::npos && colon < end) {
                for (std::size_t k = p; k < colon; ++k) {
                    const char c = lower(clean[k]);
                    if (is_blank(c)) {
                        if (!label.empty() && label.back() != ' ') label += ' ';
                    } else {
                        label += c;
                    }
                }
                while (!label.empty() && label.back() == ' ') label.pop_back();
            }
            const std::size_t vb = colon == std::string::npos ? end : colon + 1;
            const std::string_view value = std::string_view(clean).substr(vb, end > vb ? end - vb : 0);
            auto numbers = [&](std::size_t min_count, std::size_t max_count, bool allow_unit) {
                std::vector<double> out;
                std::string_view s = value;
                if (allow_unit) {
                    // `initial line width: 2 pixels` / `polygons`
                    std::size_t k = s.size();
                    while (k > 0 && is_letter(s[k - 1])) --k;
                    s = s.substr(0, k);
                }
                if (!parse_numbers(s, out) || out.size() < min_count || out.size() > max_count)
                    src.fail(vb, "malformed value for '" + label + "': '" + shorten(value) + "'");
                return out;
            };
            if (label == "angle increment") {
                v.angle_increment_deg = numbers(1, 1, false)[0];
            } else if (label == "angle factor") {
                const double f = numbers(1, 1, false)[0];
                if (f == 0.0) src.fail(vb, "'angle factor' must not be 0");
                v.angle_increment_deg = 360.0 / f;
            } else if (label == "initial line width") {
                v.initial_line_width = numbers(1, 1, true)[0];
            } else if (label == "line width increment") {
                v.line_width_increment = numbers(1, 1, false)[0];
            } else if (label == "scale factor") {
                v.scale_factor = numbers(1, 1, false)[0];
            } else if (label == "tropism direction") {
                const std::vector<double> d = numbers(3, 3, false);
                const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                if (!(len > 0.0) || !std::isfinite(len)) src.fail(vb, "'tropism direction' must not be zero");
                v.tropism_direction = glm::dvec3(d[0], d[1], d[2]) / len;
                v.tropism = true;
            } else if (label == "initial elasticity" || label == "elasticity") {
                v.elasticity = numbers(1, 1, false)[0];
                v.tropism = true;
            } else if (label == "elasticity increment") {
                v.elasticity_increment = numbers(1, 1, false)[0];
            } else if (label == "tropism") {
                // cpfg 4: `tropism: T: x,y,z, A: angle, I: intensity, E: elasticity, S: step`
                std::string_view s = value;
                bool any = false;
                for (std::size_t k = 0; k + 1 < s.size(); ++k) {
                    const char key = s[k];
                    if (!((key == 'T' || key == 'E' || key == 'A' || key == 'I' || key == 'S') && s[k + 1] == ':')) continue;
                    if (k > 0 && is_letter(s[k - 1])) continue;
                    std::size_t stop = k + 2;
                    while (stop < s.size()) {
                        if (stop + 1 < s.size() && is_letter(s[stop]) && s[stop + 1] == ':') break;
                        ++stop;
                    }
                    std::vector<double> vals;
                    std::string_view field = s.substr(k + 2, stop - k - 2);
                    while (!field.empty() && (is_blank(field.back()) || field.back() == ',')) field.remove_suffix(1);
                    if (!parse_numbers(field, vals)) src.fail(vb + k, "malformed 'tropism' field '" + std::string(1, key) + ":'");
                    if (key == 'T') {
                        if (vals.size() != 3) src.fail(vb + k, "'tropism' T: needs x,y,z");
                        const double len = std::sqrt(vals[0] * vals[0] + vals[1] * vals[1] + vals[2] * vals[2]);
                        if (!(len > 0.0)) src.fail(vb + k, "'tropism direction' must not be zero");
                        v.tropism_direction = glm::dvec3(vals[0], vals[1], vals[2]) / len;
                        any = true;
                    } else if (key == 'E') {
                        if (vals.size() != 1) src.fail(vb + k, "'tropism' E: needs one value");
                        v.elasticity = vals[0];
                        any = true;
                    }
                    k = stop - 1;
                }
                if (!any) src.fail(vb, "a 'tropism:' line without T: or E:");
                v.tropism = true;
            } else {
                const std::string shown = label.empty() ? shorten(std::string_view(clean).substr(p, end - p)) : label;
                warn.add(src.where(p) + "view line '" + shown + "' is not used; skipped");
            }
        }
        if (e >= clean.size()) break;
        b = e + 1;
    }
    warn.finish(source_name);
    return v;
}

LSystemFile load_lsystem_file(const std::filesystem::path& path)
{
    auto read = [](const std::filesystem::path& p) {
        std::error_code ec;
        const auto size = std::filesystem::file_size(p, ec);
        if (ec) throw FileError(p.string(), "cannot read: " + ec.message());
        if (size > kMaxFileBytes)
            throw InvalidInput(p.string() + ":1:1: the file is " + std::to_string(size) + " bytes, over the limit of " +
                               std::to_string(kMaxFileBytes) + " bytes");
        std::ifstream in(p, std::ios::binary);
        if (!in) throw FileError(p.string(), "cannot open");
        std::string text;
        text.resize(static_cast<std::size_t>(size));
        in.read(text.data(), static_cast<std::streamsize>(size));
        if (static_cast<std::size_t>(in.gcount()) != size) throw FileError(p.string(), "cannot read the whole file");
        return text;
    };
    LSystemFile f;
    const std::string text = read(path);
    f.system = parse_lsystem(text, path.string(), &f.warnings);
    std::filesystem::path view = path;
    view.replace_extension(".v");
    std::error_code ec;
    if (view != path && std::filesystem::is_regular_file(view, ec)) {
        const std::string vtext = read(view);
        f.view = parse_view(vtext, view.string(), &f.warnings);
        f.has_view = true;
    }
    return f;
}

} // namespace lobe::lsystem
