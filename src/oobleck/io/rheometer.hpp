#pragma once
// Rheometer export files -> steps of SI columns (docs/fitting.md "Instrument exports").
//
// Formats (detected from the content, not the file name; `format` forces one):
//   trios     TA Instruments TRIOS "Export to LIMS" .txt: key<TAB>value lines, [sections], and one
//             [step] section per measured step (name line "Flow sweep - 2", column names, units,
//             tab-separated rows).
//   rheocompass  Anton Paar RheoCompass export (.csv/.txt; UTF-16, UTF-8 or Latin-1; TAB, ';' or
//             ','; decimal comma or point): Project:/Test:/Result: blocks, one step per interval
//             ("Interval data:" names, a line of [units], rows), named "RESULT - INTERVAL".
//   rspace    Malvern (NETZSCH) rSpace CSV: header "Action Name;Name(unit);…", ';' and decimal
//             comma; a new action name starts a new step.
//   csv       generic delimited text: one header row of names with optional units in brackets or
//             parentheses ("shear_rate [1/s]", "Viscosity (mPa s)"), separator (',' ';' TAB) and
//             decimal mark detected, '#' comment lines; a step_name (or step) column splits steps.
// Column names are normalized (lower case, '_' between words; "Stress" and "Shear stress" ->
// shear_stress, "Shear viscosity" -> viscosity, "Time (sequence)" -> time, "Step time" and
// "Time (action)" -> step_time, "Point No." -> point, "Shear strain" -> strain) and values converted
// to SI (mPa s -> Pa s, kPa -> Pa, % -> 1, min -> s, µN m -> N m, ...); temperatures keep their unit.
// Every error is an InputError naming the file, the line and what was expected there.
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace oobleck::io {

enum class RheometerFormat { automatic, trios, rheocompass, rspace, csv };
/// "auto", "trios", "rheocompass", "rspace", "csv".
std::string to_string(RheometerFormat f);
/// Accepts the names of to_string (and "anton-paar", "malvern"); InputError naming `where` otherwise.
RheometerFormat parse_rheometer_format(const std::string& text, const std::string& where);

/// One column of one step: numbers in SI (NaN where the file has no value), or text.
struct RheometerColumn {
  std::string name;     ///< normalized name (shear_rate, shear_stress, viscosity, time, ...)
  std::string header;   ///< the name as the file writes it
  std::string unit;     ///< the unit as the file writes it ("" when none is given)
  std::string si_unit;  ///< the unit of `values` ("1/s", "Pa", "Pa s", "s", "1" (dimensionless), ...)
  bool is_text = false;
  std::vector<double> values;     ///< numeric columns
  std::vector<std::string> text;  ///< text columns (e.g. Status)
};

struct RheometerStep {
  int index = 0;           ///< 1-based, in file order
  std::string name;        ///< e.g. "Flow sweep - 2", "Flow curve 1 - 2", "Viscometry Table"
  int line = 0;            ///< line where the step starts
  std::vector<int> lines;  ///< the file's line of each row
  std::vector<RheometerColumn> columns;
  std::size_t rows() const { return lines.size(); }
  /// The column with this normalized name, or nullptr.
  const RheometerColumn* find(const std::string& column) const;
};

struct RheometerFile {
  std::string file;
  RheometerFormat format = RheometerFormat::csv;
  std::string encoding;  ///< as detected: UTF-8, UTF-16LE, UTF-16BE, WINDOWS-1252, ISO-8859-1
  char separator = ',';
  char decimal = '.';
  /// sample, geometry, instrument, operator, date, procedure, project, test where the file names
  /// them, and every other key/value line as "Section/Key" (TRIOS) or "Key" (RheoCompass).
  std::map<std::string, std::string> attributes;
  std::vector<RheometerStep> steps;
};

/// Reads and converts one export. InputError (file:line: what was expected) for a file that fits
/// no format, an unknown unit, a unit of the wrong kind for shear_rate/shear_stress/viscosity/time,
/// a value that is not a number, or a file without any data row.
RheometerFile read_rheometer(const std::string& path, RheometerFormat format = RheometerFormat::automatic);

/// Indices into f.steps selected by `spec`: a 1-based index, or a name matched case-insensitively,
/// first as written, then without TRIOS's " - N" suffix ("flow sweep" selects "Flow sweep - 2"; a
/// name that several steps share selects all of them). InputError naming `option` and listing the
/// steps when nothing matches.
std::vector<std::size_t> select_steps(const RheometerFile& f, const std::string& spec,
                                      const std::string& option = "--step");

/// The steps' rows as one table: step, step_name, time, shear_rate, shear_stress, viscosity, then
/// every other column in order of first appearance (NaN / "" where a step lacks it).
struct RheometerTable {
  struct Column {
    std::string name, si_unit, units_read;  ///< units_read: the file's spellings, ", "-joined
    bool is_text = false;
    std::vector<double> values;
    std::vector<std::string> text;
  };
  std::vector<Column> columns;
  std::size_t rows = 0;
};
/// `steps`: indices into f.steps (empty: every step).
RheometerTable to_table(const RheometerFile& f, const std::vector<std::size_t>& steps = {});

/// Shear rate [1/s] and shear stress [Pa] of the flow-curve rows, for `rheology fit --kind curves`.
struct FlowCurveRows {
  std::vector<double> shear_rate, shear_stress;
  std::vector<std::size_t> steps;  ///< indices into f.steps used
  std::size_t skipped = 0;         ///< rows without both values (empty fields)
};
/// `step_spec` as select_steps; empty: the one step with shear_rate and shear_stress columns
/// (InputError listing them when there are several). Rows missing either value are skipped; a
/// value <= 0 is an InputError naming file:line.
FlowCurveRows flow_curve_rows(const RheometerFile& f, const std::string& step_spec,
                              const std::string& option = "--step");

}  // namespace oobleck::io
