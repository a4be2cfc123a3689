// Rheometer export readers (rheometer.hpp). The text is decoded to UTF-8 with iconv, each line is
// split into fields by libcsv (quotes, the detected separator), and every format then yields raw
// steps (names, units, cells with their line numbers) that one routine converts to SI columns.
#include "oobleck/io/rheometer.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include <csv.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <iconv.h>

#include "oobleck/core/error.hpp"

namespace oobleck::io {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- text ------------------------------------------------------------------------------------

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool starts_with_ci(const std::string& s, std::string_view prefix) {
  return s.size() >= prefix.size() && lower(s.substr(0, prefix.size())) == lower(std::string(prefix));
}

/// `bytes` converted from `from` to UTF-8 by iconv; nullopt when they are not valid in `from`.
std::optional<std::string> iconv_to_utf8(const std::string& bytes, const char* from) {
  iconv_t cd = ::iconv_open("UTF-8", from);
  // NOLINTNEXTLINE(performance-no-int-to-ptr): iconv_open's error value is (iconv_t)-1
  if (cd == reinterpret_cast<iconv_t>(-1)) return std::nullopt;
  std::string out(bytes.size() * 2 + 16, '\0');
  std::string in = bytes;
  char* ip = in.data();
  std::size_t il = in.size();
  std::size_t done = 0;
  bool ok = true;
  while (il > 0) {
    char* op = out.data() + done;
    std::size_t ol = out.size() - done;
    const std::size_t r = ::iconv(cd, &ip, &il, &op, &ol);
    done = static_cast<std::size_t>(op - out.data());
    if (r == static_cast<std::size_t>(-1)) {
      if (errno == E2BIG) {
        out.resize(out.size() * 2);
        continue;
      }
      ok = false;  // EILSEQ, EINVAL: not valid in `from`
      break;
    }
  }
  ::iconv_close(cd);
  if (!ok) return std::nullopt;
  out.resize(done);
  return out;
}

struct Text {
  std::vector<std::string> lines;  ///< lines[k] is line k + 1, without its end of line
  std::string encoding;
};

/// The file's text in UTF-8: a BOM (UTF-8, UTF-16LE/BE) decides; UTF-16 without one is recognised
/// by its zero bytes; other text is UTF-8 when valid, else Windows-1252 (Latin-1).
Text read_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(fmt::format("{}: not a regular file (a directory or device cannot be a data file)", path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open data file", path));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Text t;
  auto byte = [&](std::size_t k) { return k < bytes.size() ? static_cast<unsigned char>(bytes[k]) : 0x100u; };
  std::optional<std::string> utf8;
  if (byte(0) == 0xEF && byte(1) == 0xBB && byte(2) == 0xBF) {
    t.encoding = "UTF-8";
    utf8 = iconv_to_utf8(bytes.substr(3), "UTF-8");
  } else if ((byte(0) == 0xFF && byte(1) == 0xFE) || (byte(0) != 0 && byte(1) == 0 && bytes.size() >= 2)) {
    t.encoding = "UTF-16LE";
    utf8 = iconv_to_utf8(byte(0) == 0xFF && byte(1) == 0xFE ? bytes.substr(2) : bytes, "UTF-16LE");
  } else if ((byte(0) == 0xFE && byte(1) == 0xFF) || (byte(0) == 0 && byte(1) != 0 && bytes.size() >= 2)) {
    t.encoding = "UTF-16BE";
    utf8 = iconv_to_utf8(byte(0) == 0xFE && byte(1) == 0xFF ? bytes.substr(2) : bytes, "UTF-16BE");
  } else {
    t.encoding = "UTF-8";
    utf8 = iconv_to_utf8(bytes, "UTF-8");
    if (!utf8) {
      t.encoding = "WINDOWS-1252";
      utf8 = iconv_to_utf8(bytes, "WINDOWS-1252");
    }
    if (!utf8) {
      t.encoding = "ISO-8859-1";
      utf8 = iconv_to_utf8(bytes, "ISO-8859-1");
    }
  }
  if (!utf8)
    throw InputError(fmt::format("{}: not valid {} text (expected a text export of a rheometer)", path, t.encoding));
  if (utf8->find('\0') != std::string::npos)
    throw InputError(fmt::format("{}: contains NUL characters (expected a text export of a rheometer)", path));
  std::string line;
  std::istringstream ss(*utf8);
  while (std::getline(ss, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    t.lines.push_back(line);
  }
  return t;
}

/// The fields of one line split at `sep` by libcsv (double quotes group, "" escapes a quote);
/// spaces around a field are removed.
std::vector<std::string> split(const std::string& line, char sep) {
  struct Acc {
    std::vector<std::string> fields;
  } acc;
  csv_parser p{};
  if (csv_init(&p, 0) != 0) throw std::bad_alloc();
  csv_set_delim(&p, static_cast<unsigned char>(sep));
  csv_set_space_func(&p, [](unsigned char c) -> int { return c == ' ' ? 1 : 0; });
  csv_set_term_func(&p, [](unsigned char) -> int { return 0; });  // one line, no terminators
  auto field = [](void* s, std::size_t len, void* data) {
    static_cast<Acc*>(data)->fields.emplace_back(s ? static_cast<const char*>(s) : "", s ? len : 0);
  };
  const std::size_t n = csv_parse(&p, line.data(), line.size(), field, nullptr, &acc);
  const bool ok = n == line.size() && csv_fini(&p, field, nullptr, &acc) == 0;
  csv_free(&p);
  if (!ok) throw std::bad_alloc();  // non-strict libcsv fails only for memory
  if (acc.fields.empty()) acc.fields.emplace_back();
  for (auto& f : acc.fields) f = trim(f);
  return acc.fields;
}

bool all_empty(const std::vector<std::string>& fields) {
  return std::all_of(fields.begin(), fields.end(), [](const std::string& f) { return f.empty(); });
}

/// A number in the file's convention: decimal mark `decimal`, optional exponent and sign.
std::optional<double> parse_number(std::string s, char decimal) {
  if (decimal == ',') std::replace(s.begin(), s.end(), ',', '.');
  if (!s.empty() && s[0] == '+') s.erase(0, 1);
  double v = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

/// The decimal mark of data fields: ',' when a field reads as digits, a comma and digits (with
/// the separator not a comma), else '.'.
char detect_decimal(const std::vector<std::string>& lines, std::size_t from, char sep) {
  if (sep == ',') return '.';
  for (std::size_t k = from; k < lines.size(); ++k) {
    for (const auto& f : split(lines[k], sep)) {
      const auto c = f.find(',');
      if (c == std::string::npos || c == 0 || c + 1 >= f.size()) continue;
      if (std::isdigit(static_cast<unsigned char>(f[c - 1])) && std::isdigit(static_cast<unsigned char>(f[c + 1])) &&
          parse_number(f, ','))
        return ',';
    }
  }
  return '.';
}

// ---- units -----------------------------------------------------------------------------------

struct Unit {
  std::string si;  ///< SI unit of the converted value (temperatures: the unit read)
  double factor = 1.0;
};

/// A spelling reduced to one form: '·', '⋅', '*', ' ' and '.' between factors -> '.', superscripts
/// and '^' -> plain exponents, µ/μ -> u, "Pas" -> "Pa.s".
std::string canonical_unit(const std::string& u) {
  std::string s;
  for (std::size_t k = 0; k < u.size();) {
    const std::string_view rest(u.data() + k, u.size() - k);
    auto take = [&](std::string_view from, const char* to) {
      if (rest.substr(0, from.size()) != from) return false;
      s += to;
      k += from.size();
      return true;
    };
    if (take("\u00B7", ".") || take("\u22C5", ".") || take("\u2219", ".") || take("\u207B", "-") ||
        take("\u00B9", "1") || take("\u00B2", "2") || take("\u00B3", "3") || take("\u00B5", "u") ||
        take("\u03BC", "u") || take("\u2212", "-") || take("^", "") || take("*", ".") || take(" ", "."))
      continue;
    s += u[k++];
  }
  if (s == "Pas") return "Pa.s";
  if (s == "mPas") return "mPa.s";
  return s;
}

std::optional<Unit> lookup_unit(const std::string& unit) {
  static const std::map<std::string, Unit> table = {// dimensionless
                                                    {"", {"", 1.0}},
                                                    {"1", {"1", 1.0}},
                                                    {"-", {"1", 1.0}},
                                                    {"%", {"1", 1e-2}},
                                                    // viscosity
                                                    {"Pa.s", {"Pa s", 1.0}},
                                                    {"mPa.s", {"Pa s", 1e-3}},
                                                    {"kPa.s", {"Pa s", 1e3}},
                                                    {"cP", {"Pa s", 1e-3}},
                                                    {"P", {"Pa s", 0.1}},
                                                    // stress, modulus
                                                    {"Pa", {"Pa", 1.0}},
                                                    {"mPa", {"Pa", 1e-3}},
                                                    {"kPa", {"Pa", 1e3}},
                                                    {"MPa", {"Pa", 1e6}},
                                                    // shear rate, frequency
                                                    {"1/s", {"1/s", 1.0}},
                                                    {"s-1", {"1/s", 1.0}},
                                                    {"/s", {"1/s", 1.0}},
                                                    {"Hz", {"Hz", 1.0}},
                                                    {"rad/s", {"rad/s", 1.0}},
                                                    {"rpm", {"rad/s", 2.0 * std::numbers::pi / 60.0}},
                                                    {"1/min", {"1/s", 1.0 / 60.0}},
                                                    // time
                                                    {"s", {"s", 1.0}},
                                                    {"ms", {"s", 1e-3}},
                                                    {"min", {"s", 60.0}},
                                                    {"h", {"s", 3600.0}},
                                                    // torque, force
                                                    {"N.m", {"N m", 1.0}},
                                                    {"mN.m", {"N m", 1e-3}},
                                                    {"uN.m", {"N m", 1e-6}},
                                                    {"nN.m", {"N m", 1e-9}},
                                                    {"N", {"N", 1.0}},
                                                    {"mN", {"N", 1e-3}},
                                                    // length, speed, angle
                                                    {"m", {"m", 1.0}},
                                                    {"cm", {"m", 1e-2}},
                                                    {"mm", {"m", 1e-3}},
                                                    {"um", {"m", 1e-6}},
                                                    {"m/s", {"m/s", 1.0}},
                                                    {"mm/s", {"m/s", 1e-3}},
                                                    {"rad", {"rad", 1.0}},
                                                    {"mrad", {"rad", 1e-3}},
                                                    {"urad", {"rad", 1e-6}},
                                                    {"\u00B0", {"rad", std::numbers::pi / 180.0}},
                                                    {"deg", {"rad", std::numbers::pi / 180.0}},
                                                    // temperature: kept as read
                                                    {"\u00B0C", {"\u00B0C", 1.0}},
                                                    {"C", {"\u00B0C", 1.0}},
                                                    {"K", {"K", 1.0}},
                                                    // power, energy
                                                    {"W", {"W", 1.0}},
                                                    {"mW", {"W", 1e-3}},
                                                    {"J", {"J", 1.0}},
                                                    {"mJ", {"J", 1e-3}}};
  const auto it = table.find(canonical_unit(unit));
  if (it == table.end()) return std::nullopt;
  return it->second;
}

constexpr const char* kKnownUnits =
    "Pa s, mPa s, cP; Pa, kPa, MPa; 1/s, s-1, s^-1, s\u207B\u00B9; %, 1; s, min, ms; N m, mN m, \u00B5N m; N, mN; "
    "m, mm, \u00B5m; rad, mrad, \u00B0; rad/s, Hz, rpm; \u00B0C, K; W, J ('\u00B7', '.' or ' ' between factors)";

// ---- names -----------------------------------------------------------------------------------

/// Lower case, one '_' between words; aliases of the core quantities mapped to their names.
std::string normalize_name(const std::string& header) {
  std::string s;
  for (unsigned char c : header) {
    if (std::isalnum(c)) {
      s += static_cast<char>(std::tolower(c));
    } else if (!s.empty() && s.back() != '_') {
      s += '_';
    }
  }
  while (!s.empty() && s.back() == '_') s.pop_back();
  static const std::map<std::string, std::string> aliases = {
      {"stress", "shear_stress"},   {"shear_viscosity", "viscosity"}, {"time_sequence", "time"},
      {"time_action", "step_time"}, {"interval_time", "step_time"},   {"point_no", "point"},
      {"shear_strain", "strain"},   {"point_number", "point"},        {"total_time", "time"},
  };
  const auto it = aliases.find(s);
  return it == aliases.end() ? s : it->second;
}

/// SI unit a core column must have, or nullptr.
const char* required_si(const std::string& name) {
  if (name == "shear_rate") return "1/s";
  if (name == "shear_stress") return "Pa";
  if (name == "viscosity") return "Pa s";
  if (name == "time" || name == "step_time") return "s";
  if (name == "strain") return "1";
  return nullptr;
}

/// "Name [unit]" or "Name (unit)" (the last bracket group at the end) -> name, unit.
std::pair<std::string, std::string> split_unit(const std::string& field) {
  const std::string f = trim(field);
  if (f.size() >= 2 && (f.back() == ']' || f.back() == ')')) {
    const char open = f.back() == ']' ? '[' : '(';
    const auto b = f.rfind(open);
    if (b != std::string::npos && b > 0) return {trim(f.substr(0, b)), trim(f.substr(b + 1, f.size() - b - 2))};
  }
  return {f, ""};
}

// ---- raw steps -------------------------------------------------------------------------------

struct RawStep {
  int index = 0;  ///< the file's own step number where it has one (generic CSV's step column), else 0
  std::string name;
  int line = 0;
  std::vector<std::string> headers, units;
  std::vector<int> unit_lines;  ///< where each unit was read
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;
  bool units_required = true;  ///< instrument formats: a core column needs a unit
};

struct Reader {
  std::string path;
  const Text& text;
  RheometerFile out;
  std::vector<RawStep> steps;

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}", path, line, what));
  }
  const std::string& line(std::size_t k) const { return text.lines[k]; }
  int lineno(std::size_t k) const { return static_cast<int>(k) + 1; }

  RheometerStep convert(const RawStep& raw, int index) const;
};

RheometerStep Reader::convert(const RawStep& raw, int index) const {
  RheometerStep step;
  step.index = raw.index > 0 ? raw.index : index;
  step.name = raw.name;
  step.line = raw.line;
  step.lines = raw.lines;
  const std::string where_fmt = out.format == RheometerFormat::csv ? "the header" : "the unit line";
  std::set<std::string> names;
  for (std::size_t j = 0; j < raw.headers.size(); ++j) {
    RheometerColumn c;
    c.header = raw.headers[j];
    c.unit = j < raw.units.size() ? raw.units[j] : "";
    const int uline = j < raw.unit_lines.size() ? raw.unit_lines[j] : raw.line;
    c.name = normalize_name(c.header);
    if (c.name.empty()) {
      if (c.header.empty() &&
          std::all_of(raw.rows.begin(), raw.rows.end(), [&](const auto& r) { return j >= r.size() || r[j].empty(); }))
        continue;  // an unnamed, empty column (a trailing separator)
      c.name = fmt::format("column_{}", j + 1);
    }
    for (int k = 2; names.count(c.name) > 0; ++k) c.name = fmt::format("{}_{}", normalize_name(c.header), k);
    names.insert(c.name);
    const char* need = required_si(c.name);
    // Text: a column without unit and not a core quantity whose cells are not all numbers.
    const bool numeric_cells = std::all_of(raw.rows.begin(), raw.rows.end(), [&](const auto& r) {
      if (j >= r.size() || r[j].empty()) return true;
      const auto v = parse_number(r[j], out.decimal);
      return v.has_value();
    });
    if (!numeric_cells && c.unit.empty() && need == nullptr) {
      c.is_text = true;
      for (const auto& r : raw.rows) c.text.push_back(j < r.size() ? r[j] : "");
      step.columns.push_back(std::move(c));
      continue;
    }
    if (c.unit.empty() && need != nullptr && raw.units_required && std::string(need) != "1") {
      fail(uline, fmt::format("column '{}' has no unit: expected its unit ({}) in {}", c.header, need, where_fmt));
    }
    const auto u = lookup_unit(c.unit);
    if (!u) {
      fail(uline, fmt::format("column '{}': unknown unit '{}'; expected one of {}", c.header, c.unit, kKnownUnits));
    }
    if (need != nullptr && !c.unit.empty() && u->si != need) {
      fail(uline, fmt::format("column '{}' is {} but its unit '{}' is not one of {} (expected a unit of {})", c.header,
                              c.name, c.unit, need, need));
    }
    c.si_unit = c.unit.empty() && need != nullptr ? need : u->si;
    c.values.reserve(raw.rows.size());
    for (std::size_t k = 0; k < raw.rows.size(); ++k) {
      const auto& r = raw.rows[k];
      if (j >= r.size() || r[j].empty()) {
        c.values.push_back(kNaN);
        continue;
      }
      const auto v = parse_number(r[j], out.decimal);
      if (!v || std::isinf(*v)) {
        fail(raw.lines[k], fmt::format("column '{}': '{}' is not a finite number (expected a number with decimal "
                                       "{} '{}')",
                                       c.header, r[j], out.decimal == ',' ? "comma" : "point", out.decimal));
      }
      c.values.push_back(*v * u->factor);
    }
    step.columns.push_back(std::move(c));
  }
  return step;
}

/// Data rows must not hold more non-empty fields than there are column names.
void check_width(const Reader& r, const std::vector<std::string>& fields, std::size_t columns, int line) {
  for (std::size_t j = columns; j < fields.size(); ++j) {
    if (!fields[j].empty()) {
      r.fail(line, fmt::format("{} values but {} column names (expected at most one value per named column)",
                               fields.size(), columns));
    }
  }
}

// ---- TA TRIOS "Export to LIMS" ----------------------------------------------------------------

bool is_section(const std::string& s) { return s.size() >= 2 && s.front() == '[' && s.back() == ']'; }

void read_trios(Reader& r) {
  r.out.separator = '\t';
  r.out.decimal = '.';
  std::string section, last_key;
  std::vector<std::string> procedure_steps;
  const std::size_t n = r.text.lines.size();
  std::size_t k = 0;
  while (k < n) {
    const std::string s = trim(r.line(k));
    if (s.empty()) {
      ++k;
      continue;
    }
    if (lower(s) == "[step]") {
      RawStep st;
      st.line = r.lineno(k);
      auto next_nonempty = [&](std::size_t from) {
        while (from < n && trim(r.line(from)).empty()) ++from;
        return from;
      };
      const std::size_t kn = next_nonempty(k + 1);
      if (kn >= n || is_section(trim(r.line(kn))))
        r.fail(st.line, "[step] without a step name: expected the name (e.g. 'Flow sweep - 2') on the next line");
      st.name = trim(r.line(kn));
      const std::size_t kh = kn + 1;
      if (kh >= n || trim(r.line(kh)).empty() || is_section(trim(r.line(kh))))
        r.fail(r.lineno(std::min(kh, n - 1)),
               fmt::format("step '{}': expected a TAB-separated line of column names after the step name", st.name));
      st.headers = split(r.line(kh), '\t');
      while (!st.headers.empty() && st.headers.back().empty()) st.headers.pop_back();
      const std::size_t ku = kh + 1;
      if (ku >= n || is_section(trim(r.line(ku))))
        r.fail(r.lineno(std::min(ku, n - 1)),
               fmt::format("step '{}': expected a TAB-separated line of units after the column names", st.name));
      st.units = split(r.line(ku), '\t');
      st.unit_lines.assign(st.headers.size(), r.lineno(ku));
      check_width(r, st.units, st.headers.size(), r.lineno(ku));
      // A units line is text: a first cell that reads as a number means the line is missing.
      if (!st.units.empty() && !st.units[0].empty() && parse_number(st.units[0], '.'))
        r.fail(r.lineno(ku), fmt::format("step '{}': '{}' is a number: expected the line of units (s, Pa, 1/s, ...) "
                                         "after the column names",
                                         st.name, st.units[0]));
      k = ku + 1;
      for (; k < n; ++k) {
        const std::string d = trim(r.line(k));
        if (d.empty() || is_section(d)) break;
        auto fields = split(r.line(k), '\t');
        check_width(r, fields, st.headers.size(), r.lineno(k));
        st.rows.push_back(std::move(fields));
        st.lines.push_back(r.lineno(k));
      }
      r.steps.push_back(std::move(st));
      continue;
    }
    if (is_section(s)) {
      section = s.substr(1, s.size() - 2);
      ++k;
      continue;
    }
    const auto fields = split(r.line(k), '\t');
    if (fields[0].empty() && section.empty() && last_key == "Procedure name") {
      if (fields.size() > 1 && !fields[1].empty()) procedure_steps.push_back(fields[1]);
    } else if (!fields[0].empty()) {
      last_key = fields[0];
      std::string value;
      for (std::size_t j = 1; j < fields.size(); ++j) {
        if (fields[j].empty()) continue;
        if (!value.empty()) value += ' ';
        value += fields[j];
      }
      r.out.attributes[section.empty() ? last_key : fmt::format("{}/{}", section, last_key)] = value;
    }
    ++k;
  }
  static const std::map<std::string, std::string> named = {
      {"Sample name", "sample"}, {"Geometry name", "geometry"}, {"Instrument name", "instrument"},
      {"Operator", "operator"},  {"rundate", "date"},           {"Procedure name", "procedure"}};
  for (const auto& [key, name] : named) {
    const auto it = r.out.attributes.find(key);
    if (it != r.out.attributes.end()) {
      r.out.attributes[name] = it->second;
      r.out.attributes.erase(it);
    }
  }
  if (!procedure_steps.empty())
    r.out.attributes["procedure_steps"] = fmt::format("{}", fmt::join(procedure_steps, "#"));
  if (r.steps.empty())
    throw InputError(
        fmt::format("{}: no [step] section: expected a TA TRIOS 'Export to LIMS' file with [step] "
                    "sections (name, column names, units, data rows)",
                    r.path));
}

// ---- Anton Paar RheoCompass -------------------------------------------------------------------

const std::vector<std::string>& rheocompass_labels() {
  static const std::vector<std::string> labels = {
      "Project:", "Test:", "Result:", "Interval and data points:", "Interval data:"};
  return labels;
}

/// The separator after a RheoCompass label at the start of `line`, or 0.
char rheocompass_separator(const std::string& line) {
  std::string s = line;
  const auto b = s.find_first_not_of(" \"");
  if (b == std::string::npos) return 0;
  s = s.substr(b);
  for (const auto& l : rheocompass_labels()) {
    if (starts_with_ci(s, l)) {
      std::size_t k = l.size();
      if (k < s.size() && s[k] == '"') ++k;
      if (k < s.size() && (s[k] == '\t' || s[k] == ';' || s[k] == ',')) return s[k];
    }
  }
  return 0;
}

bool is_label(const std::string& field) {
  return std::any_of(rheocompass_labels().begin(), rheocompass_labels().end(),
                     [&](const std::string& l) { return lower(field) == lower(l); });
}

void read_rheocompass(Reader& r) {
  const std::size_t n = r.text.lines.size();
  char sep = 0;
  for (std::size_t k = 0; k < n && sep == 0; ++k) sep = rheocompass_separator(r.line(k));
  if (sep == 0)
    throw InputError(
        fmt::format("{}: no 'Project:', 'Test:', 'Result:' or 'Interval data:' line followed by a TAB, "
                    "';' or ',': expected an Anton Paar RheoCompass export",
                    r.path));
  r.out.separator = sep;
  r.out.decimal = detect_decimal(r.text.lines, 0, sep);
  std::string result, interval;
  std::size_t k = 0;
  while (k < n) {
    auto fields = split(r.line(k), sep);
    if (all_empty(fields)) {
      ++k;
      continue;
    }
    const std::string label = fields[0];
    auto value = [&] { return fields.size() > 1 ? fields[1] : std::string(); };
    if (lower(label) == "project:") {
      r.out.attributes["project"] = value();
    } else if (lower(label) == "test:") {
      r.out.attributes["test"] = value();
      r.out.attributes.emplace("sample", value());
    } else if (lower(label) == "result:") {
      result = value();
      interval.clear();
    } else if (lower(label) == "interval and data points:") {
      interval = value();
    } else if (lower(label) == "interval data:") {
      RawStep st;
      st.line = r.lineno(k);
      if (result.empty()) result = r.out.attributes.count("test") ? r.out.attributes["test"] : "Result";
      if (interval.empty())
        interval = std::to_string(1 + std::count_if(r.steps.begin(), r.steps.end(), [&](const RawStep& s) {
                                    return s.name.rfind(result + " - ", 0) == 0;
                                  }));
      st.name = fmt::format("{} - {}", result, interval);
      st.headers.assign(fields.begin() + 1, fields.end());
      while (!st.headers.empty() && st.headers.back().empty()) st.headers.pop_back();
      if (st.headers.empty())
        r.fail(st.line, "'Interval data:' without column names: expected 'Interval data:', then Point No., Time, ...");
      // Lines of empty fields, then the units line (every field empty or in brackets).
      std::size_t ku = k + 1;
      while (ku < n && all_empty(split(r.line(ku), sep))) ++ku;
      const auto units = ku < n ? split(r.line(ku), sep) : std::vector<std::string>{};
      const bool units_ok = ku < n && !units.empty() && std::all_of(units.begin() + 1, units.end(), [](const auto& u) {
                              return u.empty() || (u.front() == '[' && u.back() == ']');
                            });
      if (!units_ok)
        r.fail(r.lineno(std::min(ku, n - 1)),
               fmt::format("interval '{}': expected the line of units in brackets ([s], [1/s], [Pa], ...) after the "
                           "column names of line {}",
                           st.name, st.line));
      for (std::size_t j = 0; j < st.headers.size(); ++j) {
        std::string u = j + 1 < units.size() ? units[j + 1] : "";
        if (u.size() >= 2 && u.front() == '[') u = trim(u.substr(1, u.size() - 2));
        st.units.push_back(u);
        st.unit_lines.push_back(r.lineno(ku));
      }
      k = ku + 1;
      for (; k < n; ++k) {
        auto d = split(r.line(k), sep);
        if (all_empty(d)) continue;
        if (is_label(d[0]) || (!d[0].empty() && d[0].back() == ':')) break;
        std::vector<std::string> row(d.begin() + 1, d.end());
        check_width(r, row, st.headers.size(), r.lineno(k));
        st.rows.push_back(std::move(row));
        st.lines.push_back(r.lineno(k));
      }
      r.steps.push_back(std::move(st));
      continue;
    } else if (!label.empty() && label.back() == ':') {
      r.out.attributes[label.substr(0, label.size() - 1)] = value();
    } else {
      r.fail(r.lineno(k), fmt::format("'{}': expected a RheoCompass label (Project:, Test:, Result:, Interval and data "
                                      "points:, Interval data:) or a data row of an interval",
                                      label));
    }
    ++k;
  }
  if (r.steps.empty())
    throw InputError(
        fmt::format("{}: no 'Interval data:' line: expected an Anton Paar RheoCompass export with at "
                    "least one interval (names, units, data rows)",
                    r.path));
}

// ---- Malvern rSpace --------------------------------------------------------------------------

std::optional<std::size_t> first_content_line(const Text& t) {
  for (std::size_t k = 0; k < t.lines.size(); ++k) {
    if (!trim(t.lines[k]).empty()) return k;
  }
  return std::nullopt;
}

char rspace_separator(const std::string& line) {
  std::string s = trim(line);
  if (!s.empty() && s[0] == '"') s.erase(0, 1);
  if (!starts_with_ci(s, "Action Name")) return 0;
  std::size_t k = 11;
  if (k < s.size() && s[k] == '"') ++k;
  if (k < s.size() && (s[k] == ';' || s[k] == '\t' || s[k] == ',')) return s[k];
  return 0;
}

void read_rspace(Reader& r) {
  const auto first = first_content_line(r.text);
  const char sep = first ? rspace_separator(r.line(*first)) : 0;
  if (sep == 0)
    throw InputError(
        fmt::format("{}:{}: expected the rSpace header 'Action Name;Name(unit);...'", r.path, first ? *first + 1 : 1));
  r.out.separator = sep;
  r.out.decimal = detect_decimal(r.text.lines, *first + 1, sep);
  const auto header = split(r.line(*first), sep);
  std::vector<std::string> names, units;
  for (std::size_t j = 1; j < header.size(); ++j) {
    auto [name, unit] = split_unit(header[j]);
    names.push_back(name);
    units.push_back(unit);
  }
  while (!names.empty() && names.back().empty()) {
    names.pop_back();
    units.pop_back();
  }
  for (std::size_t k = *first + 1; k < r.text.lines.size(); ++k) {
    auto fields = split(r.line(k), sep);
    if (all_empty(fields)) continue;
    if (fields[0].empty())
      r.fail(r.lineno(k), "empty action name: expected every rSpace data row to start with its action (step) name");
    if (r.steps.empty() || r.steps.back().name != fields[0]) {
      RawStep st;
      st.name = fields[0];
      st.line = r.lineno(k);
      st.headers = names;
      st.units = units;
      st.unit_lines.assign(names.size(), r.lineno(*first));
      r.steps.push_back(std::move(st));
    }
    std::vector<std::string> row(fields.begin() + 1, fields.end());
    check_width(r, row, names.size(), r.lineno(k));
    r.steps.back().rows.push_back(std::move(row));
    r.steps.back().lines.push_back(r.lineno(k));
  }
}

// ---- generic CSV -----------------------------------------------------------------------------

void read_generic(Reader& r) {
  std::optional<std::size_t> header_line;
  for (std::size_t k = 0; k < r.text.lines.size(); ++k) {
    const std::string s = trim(r.line(k));
    if (!s.empty() && s[0] != '#') {
      header_line = k;
      break;
    }
  }
  if (!header_line) throw InputError(fmt::format("{}: no header row (expected a row of column names)", r.path));
  const std::string& h = r.line(*header_line);
  char sep = 0;
  for (char c : {'\t', ';', ','}) {
    if (sep == 0 && split(h, c).size() >= 2) sep = c;
  }
  if (sep == 0)
    r.fail(r.lineno(*header_line),
           fmt::format("'{}' fits no format: expected a TRIOS export ('Filename<TAB>…', [step] sections), a "
                       "RheoCompass export ('Project:', 'Interval data:' lines), an rSpace CSV ('Action Name;…') or a "
                       "header row of two or more column names separated by ',', ';' or TAB",
                       trim(h).substr(0, 60)));
  r.out.separator = sep;
  r.out.decimal = detect_decimal(r.text.lines, *header_line + 1, sep);
  std::vector<std::string> names, units;
  for (const auto& f : split(h, sep)) {
    auto [name, unit] = split_unit(f);
    names.push_back(name);
    units.push_back(unit);
  }
  while (!names.empty() && names.back().empty()) {
    names.pop_back();
    units.pop_back();
  }
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (names[j].empty())
      r.fail(r.lineno(*header_line),
             fmt::format("column {}: empty name in the header (expected a name for every column)", j + 1));
    if (parse_number(names[j], r.out.decimal))
      r.fail(r.lineno(*header_line), fmt::format("'{}' is a number: expected a header row of column names", names[j]));
  }
  // step / step_name columns split steps (the file `oobleck rheology import` writes).
  std::optional<std::size_t> j_step, j_name;
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (normalize_name(names[j]) == "step") j_step = j;
    if (normalize_name(names[j]) == "step_name") j_name = j;
  }
  std::vector<std::string> col_names, col_units;
  std::vector<std::size_t> keep;
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (j == j_step || j == j_name) continue;
    keep.push_back(j);
    col_names.push_back(names[j]);
    col_units.push_back(units[j]);
  }
  const std::string stem = std::filesystem::path(r.path).stem().string();
  std::string last_key;
  for (std::size_t k = *header_line + 1; k < r.text.lines.size(); ++k) {
    const std::string s = trim(r.line(k));
    if (s.empty() || s[0] == '#') continue;
    auto fields = split(r.line(k), sep);
    if (fields.size() > names.size()) check_width(r, fields, names.size(), r.lineno(k));
    if (fields.size() < names.size())
      r.fail(r.lineno(k), fmt::format("{} values but the header (line {}) has {} columns: expected one value per "
                                      "column (an empty field for a missing one)",
                                      fields.size(), *header_line + 1, names.size()));
    std::string key, name = stem;
    if (j_name) name = key = fields[*j_name];
    if (j_step) {
      key += "\x1f" + fields[*j_step];
      if (!j_name) name = "step " + fields[*j_step];
    }
    if (r.steps.empty() || key != last_key) {
      RawStep st;
      st.name = name;
      st.line = r.lineno(k);
      st.headers = col_names;
      st.units = col_units;
      st.unit_lines.assign(col_names.size(), r.lineno(*header_line));
      st.units_required = false;
      if (j_step) {
        const auto v = parse_number(fields[*j_step], r.out.decimal);
        if (v && *v >= 1.0 && *v < 1e6 && *v == std::floor(*v)) st.index = static_cast<int>(*v);
      }
      r.steps.push_back(std::move(st));
      last_key = key;
    }
    std::vector<std::string> row;
    row.reserve(keep.size());
    for (std::size_t j : keep) row.push_back(fields[j]);
    r.steps.back().rows.push_back(std::move(row));
    r.steps.back().lines.push_back(r.lineno(k));
  }
}

// ---- detection -------------------------------------------------------------------------------

RheometerFormat detect(const Text& t) {
  const auto first = first_content_line(t);
  if (!first) return RheometerFormat::csv;
  const std::string head = trim(t.lines[*first]);
  if (starts_with_ci(head, "Filename\t")) return RheometerFormat::trios;
  if (rspace_separator(head) != 0) return RheometerFormat::rspace;
  if (rheocompass_separator(head) != 0) return RheometerFormat::rheocompass;
  for (const auto& l : t.lines) {
    if (lower(trim(l)) == "[step]") return RheometerFormat::trios;
    if (rheocompass_separator(l) != 0 && starts_with_ci(trim(l), "Interval data:")) return RheometerFormat::rheocompass;
  }
  return RheometerFormat::csv;
}

struct FormatName {
  RheometerFormat format;
  const char* key;    ///< to_string / --format
  const char* title;  ///< in messages
};
constexpr FormatName kFormats[] = {{RheometerFormat::automatic, "auto", "any"},
                                   {RheometerFormat::trios, "trios", "TA TRIOS 'Export to LIMS'"},
                                   {RheometerFormat::rheocompass, "rheocompass", "Anton Paar RheoCompass"},
                                   {RheometerFormat::rspace, "rspace", "Malvern rSpace"},
                                   {RheometerFormat::csv, "csv", "CSV"}};

std::string format_name(RheometerFormat f) {
  for (const auto& n : kFormats) {
    if (n.format == f) return n.title;
  }
  return "?";
}

std::string step_key(const std::string& name) {
  std::string s = lower(trim(name));
  // TRIOS's " - N" (and RheoCompass's " - INTERVAL") index suffix.
  const auto dash = s.rfind(" - ");
  if (dash != std::string::npos && dash + 3 < s.size() &&
      std::all_of(s.begin() + static_cast<std::ptrdiff_t>(dash + 3), s.end(),
                  [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }))
    s.resize(dash);
  return trim(s);
}

std::string list_steps(const RheometerFile& f) {
  std::vector<std::string> items;
  for (const auto& s : f.steps) items.push_back(fmt::format("{} '{}'", s.index, s.name));
  return fmt::format("{}", fmt::join(items, ", "));
}

}  // namespace

const RheometerColumn* RheometerStep::find(const std::string& column) const {
  for (const auto& c : columns) {
    if (c.name == column) return &c;
  }
  return nullptr;
}

std::string to_string(RheometerFormat f) {
  for (const auto& n : kFormats) {
    if (n.format == f) return n.key;
  }
  return "?";
}

RheometerFormat parse_rheometer_format(const std::string& text, const std::string& where) {
  const std::string s = lower(text);
  if (s == "auto") return RheometerFormat::automatic;
  if (s == "trios") return RheometerFormat::trios;
  if (s == "rheocompass" || s == "anton-paar") return RheometerFormat::rheocompass;
  if (s == "rspace" || s == "malvern") return RheometerFormat::rspace;
  if (s == "csv") return RheometerFormat::csv;
  throw InputError(fmt::format("{} = '{}': must be one of auto, trios, rheocompass (anton-paar), rspace (malvern), csv",
                               where, text));
}

RheometerFile read_rheometer(const std::string& path, RheometerFormat format) {
  const Text text = read_text(path);
  Reader r{path, text, {}, {}};
  r.out.file = path;
  r.out.encoding = text.encoding;
  r.out.format = format == RheometerFormat::automatic ? detect(text) : format;
  switch (r.out.format) {
    case RheometerFormat::trios: read_trios(r); break;
    case RheometerFormat::rheocompass: read_rheocompass(r); break;
    case RheometerFormat::rspace: read_rspace(r); break;
    default: read_generic(r); break;
  }
  int index = 0;
  std::size_t rows = 0;
  for (const auto& raw : r.steps) {
    r.out.steps.push_back(r.convert(raw, ++index));
    rows += raw.rows.size();
  }
  if (rows == 0)
    throw InputError(fmt::format("{}: no data rows ({} file with {} step(s)): expected at least one row of numbers",
                                 path, format_name(r.out.format), r.out.steps.size()));
  return std::move(r.out);
}

std::vector<std::size_t> select_steps(const RheometerFile& f, const std::string& spec, const std::string& option) {
  const std::string s = trim(spec);
  if (!s.empty() &&
      std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    const int k = s.size() > 9 ? 0 : std::stoi(s);
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < f.steps.size(); ++i) {
      if (f.steps[i].index == k) out.push_back(i);
    }
    if (out.empty())
      throw InputError(fmt::format("{} = {}: {} has no step {} (steps: {})", option, s, f.file, s, list_steps(f)));
    return out;
  }
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < f.steps.size(); ++k) {
    if (lower(trim(f.steps[k].name)) == lower(s)) out.push_back(k);
  }
  if (!out.empty()) return out;
  for (std::size_t k = 0; k < f.steps.size(); ++k) {
    if (step_key(f.steps[k].name) == step_key(s)) out.push_back(k);
  }
  if (out.empty()) {
    std::vector<std::string> keys;
    for (const auto& st : f.steps) keys.push_back(step_key(st.name));
    const std::string near_key = closest_match(step_key(s), keys);
    std::string near;
    for (const auto& st : f.steps) {
      if (!near_key.empty() && near.empty() && step_key(st.name) == near_key) near = st.name;
    }
    throw InputError(fmt::format(
        "{} = '{}': no such step in {}{} (steps: {}); give a name (case-insensitive, the "
        "' - N' suffix optional) or an index",
        option, spec, f.file, near.empty() ? "" : fmt::format("; did you mean '{}'?", near), list_steps(f)));
  }
  return out;
}

RheometerTable to_table(const RheometerFile& f, const std::vector<std::size_t>& steps_in) {
  std::vector<std::size_t> steps = steps_in;
  if (steps.empty()) {
    for (std::size_t k = 0; k < f.steps.size(); ++k) steps.push_back(k);
  }
  RheometerTable t;
  auto column = [&](const std::string& name) -> RheometerTable::Column* {
    for (auto& c : t.columns) {
      if (c.name == name) return &c;
    }
    return nullptr;
  };
  t.columns.push_back({"step", "", "", false, {}, {}});
  t.columns.push_back({"step_name", "", "", true, {}, {}});
  for (const char* name : {"time", "shear_rate", "shear_stress", "viscosity"})
    t.columns.push_back({name, required_si(name), "", false, {}, {}});
  for (std::size_t s : steps) {
    for (const auto& c : f.steps.at(s).columns) {
      auto* tc = column(c.name);
      if (tc == nullptr) {
        t.columns.push_back({c.name, c.si_unit, "", c.is_text, {}, {}});
        tc = &t.columns.back();
      }
      if (!c.is_text && !c.unit.empty() &&
          (", " + tc->units_read + ", ").find(", " + c.unit + ", ") == std::string::npos)
        tc->units_read += (tc->units_read.empty() ? "" : ", ") + c.unit;
    }
  }
  for (std::size_t s : steps) {
    const auto& st = f.steps.at(s);
    const std::size_t n = st.rows();
    for (auto& tc : t.columns) {
      if (tc.name == "step") {
        tc.values.insert(tc.values.end(), n, double(st.index));
        continue;
      }
      if (tc.name == "step_name") {
        tc.text.insert(tc.text.end(), n, st.name);
        continue;
      }
      const RheometerColumn* c = st.find(tc.name);
      if (tc.is_text) {
        if (c == nullptr) {
          tc.text.insert(tc.text.end(), n, "");
        } else if (c->is_text) {
          tc.text.insert(tc.text.end(), c->text.begin(), c->text.end());
        } else {
          for (double v : c->values) tc.text.push_back(std::isnan(v) ? "" : fmt::format("{}", v));
        }
      } else if (c == nullptr || c->is_text) {
        tc.values.insert(tc.values.end(), n, kNaN);
      } else {
        if (c->si_unit != tc.si_unit)
          throw InputError(fmt::format("{}: column '{}' is in {} in step '{}' but in {} in another step", f.file,
                                       c->header, c->si_unit, st.name, tc.si_unit));
        tc.values.insert(tc.values.end(), c->values.begin(), c->values.end());
      }
    }
    t.rows += n;
  }
  return t;
}

FlowCurveRows flow_curve_rows(const RheometerFile& f, const std::string& step_spec, const std::string& option) {
  std::vector<std::size_t> steps;
  if (!trim(step_spec).empty()) {
    steps = select_steps(f, step_spec, option);
  } else {
    for (std::size_t k = 0; k < f.steps.size(); ++k) {
      const auto* g = f.steps[k].find("shear_rate");
      const auto* t = f.steps[k].find("shear_stress");
      if (g == nullptr || t == nullptr || g->is_text || t->is_text) continue;
      for (std::size_t i = 0; i < f.steps[k].rows(); ++i) {
        if (!std::isnan(g->values[i]) && !std::isnan(t->values[i])) {
          steps.push_back(k);
          break;
        }
      }
    }
    if (steps.empty())
      throw InputError(
          fmt::format("{}: no step has values of both shear rate and shear stress (steps: {}); a "
                      "flow curve needs both",
                      f.file, list_steps(f)));
    if (steps.size() > 1) {
      std::vector<std::string> names;
      names.reserve(steps.size());
      for (std::size_t k : steps) names.push_back(fmt::format("{} '{}'", f.steps[k].index, f.steps[k].name));
      throw InputError(fmt::format("{}: {} steps hold shear rate and stress ({}): choose one with {} NAME or INDEX",
                                   f.file, steps.size(), fmt::join(names, ", "), option));
    }
  }
  FlowCurveRows out;
  out.steps = steps;
  for (std::size_t k : steps) {
    const auto& st = f.steps[k];
    const auto* rate = st.find("shear_rate");
    const auto* stress = st.find("shear_stress");
    if (!rate || !stress || rate->is_text || stress->is_text)
      throw InputError(
          fmt::format("{}: step '{}' (line {}) has no {} column (columns: {}); a flow curve needs "
                      "shear rate and shear stress",
                      f.file, st.name, st.line, rate ? "shear stress" : "shear rate",
                      fmt::join(
                          [&] {
                            std::vector<std::string> h;
                            for (const auto& c : st.columns) h.push_back(c.header);
                            return h;
                          }(),
                          ", ")));
    for (std::size_t i = 0; i < st.rows(); ++i) {
      const double g = rate->values[i], t = stress->values[i];
      if (std::isnan(g) || std::isnan(t)) {
        ++out.skipped;
        continue;
      }
      if (!(g > 0.0) || !(t > 0.0))
        throw InputError(
            fmt::format("{}:{}: step '{}': shear rate {} 1/s, shear stress {} Pa: a flow curve needs "
                        "both positive",
                        f.file, st.lines[i], st.name, g, t));
      out.shear_rate.push_back(g);
      out.shear_stress.push_back(t);
    }
  }
  if (out.shear_rate.empty())
    throw InputError(fmt::format("{}: the selected step(s) hold no row with both shear rate and shear stress", f.file));
  return out;
}

}  // namespace oobleck::io
