// One run's option values, read as text and checked by the option table (see splat/options.h).
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "splat/options.h"

namespace splat {

namespace {

bool parseReal(const std::string& text, double& out) {
    if (text.empty()) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtod(text.c_str(), &end);
    return *end == '\0' && !std::isspace(static_cast<unsigned char>(text[0]));
}

bool parseInteger(const std::string& text, long long& out) {
    if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtoll(text.c_str(), &end, 10);
    return *end == '\0' && errno != ERANGE;
}

std::string flagOf(std::string_view name) { return "--" + std::string(name); }

}  // namespace

std::string checkOptionText(const OptionSpec& spec, const std::string& text) {
    double d = 0;
    long long i = 0;
    switch (spec.type) {
        case OptionType::Real:
            return parseReal(text, d) ? "" : "'" + text + "' is not a number";
        case OptionType::Integer:
            if (!parseInteger(text, i)) return "'" + text + "' is not an integer";
            return i >= -2147483647 - 1 && i <= 2147483647
                       ? ""
                       : "'" + text + "' is not an integer in range (32 bits)";
        case OptionType::Unsigned:
            return parseInteger(text, i) && i >= 0 ? "" : "'" + text + "' is not an integer >= 0";
        case OptionType::Flag:
            return text == "true" || text == "false" ? "" : "'" + text + "' is not true or false";
        case OptionType::Text:
        case OptionType::TextList:
            return "";
    }
    return "";
}

OptionValues::OptionValues(unsigned sets) : specs_(optionsOf(sets)) {
    for (const OptionSpec* spec : specs_) {
        Slot s;
        s.spec = spec;
        if (spec->type != OptionType::TextList) s.text = std::string(spec->defaultText);
        slots_.emplace(std::string(spec->name), std::move(s));
    }
}

OptionValues::Slot& OptionValues::slot(std::string_view name) {
    const auto it = slots_.find(name);
    if (it == slots_.end()) throw OptionError("unknown option " + flagOf(name));
    return it->second;
}

const OptionValues::Slot& OptionValues::slot(std::string_view name) const {
    const auto it = slots_.find(name);
    if (it == slots_.end()) throw OptionError("unknown option " + flagOf(name));
    return it->second;
}

void OptionValues::set(std::string_view name, const std::string& text, bool fromScene) {
    Slot& s = slot(name);
    const std::string why = checkOptionText(*s.spec, text);
    if (!why.empty()) throw OptionError(flagOf(name) + ": " + why);
    if (s.spec->type == OptionType::TextList)
        s.list.push_back(text);
    else if (s.spec->type == OptionType::Flag)
        s.flag = text == "true";
    else
        s.text = text;
    s.given = true;
    s.fromScene = s.fromScene || fromScene;
}

void OptionValues::markGiven(std::string_view name, bool fromScene) {
    Slot& s = slot(name);
    s.given = true;
    s.fromScene = fromScene;
}

void OptionValues::reset(std::string_view name) {
    Slot& s = slot(name);
    s.text = s.spec->type == OptionType::TextList ? "" : std::string(s.spec->defaultText);
    s.list.clear();
    s.flag = false;
}

bool OptionValues::has(std::string_view name) const { return slots_.count(name) > 0; }
bool OptionValues::given(std::string_view name) const { return slot(name).given; }
bool OptionValues::fromScene(std::string_view name) const { return slot(name).fromScene; }

bool OptionValues::differsFromDefault(std::string_view name) const {
    const Slot& s = slot(name);
    switch (s.spec->type) {
        case OptionType::Flag:
            return s.flag;
        case OptionType::TextList:
            return !s.list.empty();
        case OptionType::Real:
        case OptionType::Integer:
        case OptionType::Unsigned: {
            double a = 0, b = 0;
            if (!parseReal(s.text, a) || !parseReal(std::string(s.spec->defaultText), b))
                return true;
            return a != b;
        }
        case OptionType::Text:
            return s.text != s.spec->defaultText;
    }
    return true;
}

const std::string& OptionValues::text(std::string_view name) const { return slot(name).text; }
const std::vector<std::string>& OptionValues::list(std::string_view name) const {
    return slot(name).list;
}
bool OptionValues::flag(std::string_view name) const { return slot(name).flag; }

double OptionValues::real(std::string_view name) const {
    const Slot& s = slot(name);
    double d = 0;
    if (!parseReal(s.text, d))
        throw OptionError(flagOf(name) + ": " + checkOptionText(*s.spec, s.text));
    return d;
}

long long OptionValues::integer(std::string_view name) const {
    const Slot& s = slot(name);
    if (!checkOptionText(*s.spec, s.text).empty())
        throw OptionError(flagOf(name) + ": " + checkOptionText(*s.spec, s.text));
    long long i = 0;
    parseInteger(s.text, i);
    return i;
}

std::string& OptionValues::textSlot(std::string_view name) { return slot(name).text; }
std::vector<std::string>& OptionValues::listSlot(std::string_view name) { return slot(name).list; }
bool& OptionValues::flagSlot(std::string_view name) { return slot(name).flag; }

}  // namespace splat
