#pragma once
// The content of a report as data: sections of paragraphs, tables and
// figures. The page (index.html) and the machine summary (summary.json) are
// both written from one Document by ToHtml and ToJson, and every number goes
// through FormatCell on its way to either, so the two cannot disagree: the
// JSON holds exactly the numbers the page shows, at the precision shown.
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "ccsrm/reports/figure.h"

namespace ccsrm::reports {

// "ccsrm-report/1": the schema attribute of summary.json.
inline constexpr const char* kReportSchema = "ccsrm-report/1";

// How a number is shown.
struct NumberFormat {
  enum class Kind { kFixed, kSignificant, kInteger };
  Kind kind = Kind::kSignificant;
  int digits = 4;  // decimals (kFixed) or significant digits (kSignificant)

  static NumberFormat Fixed(int decimals) { return {Kind::kFixed, decimals}; }
  static NumberFormat Significant(int digits) { return {Kind::kSignificant, digits}; }
  static NumberFormat Integer() { return {Kind::kInteger, 0}; }
};

// One table cell: text, a number, or nothing (a NaN, or not applicable:
// "–" on the page, null in the JSON).
struct Cell {
  enum class Kind { kText, kNumber, kMissing };
  Kind kind = Kind::kMissing;
  std::string text;
  double number = 0.0;
  // Overrides the column's format when set (key-value tables whose rows
  // hold different quantities).
  bool has_format = false;
  NumberFormat format;

  static Cell Text(std::string text);
  // A NaN or infinite value becomes a missing cell.
  static Cell Number(double value);
  static Cell Number(double value, NumberFormat format);
  static Cell Missing() { return Cell(); }
};

struct Column {
  std::string key;      // JSON key of the column: lower_snake_case, unique in its table
  std::string header;   // shown on the page
  std::string unit;     // shown as "[unit]" after the header; empty for none
  NumberFormat format;  // default for the column's numbers
  // Long text (a reason, a decision): the cell wraps at a readable width
  // instead of widening the table.
  bool wrap = false;
};

struct Table {
  std::string id;  // unique in a document: JSON key and HTML id ("table-<id>")
  std::string title;
  std::string caption;  // one or two sentences under the table; may be empty
  std::vector<Column> columns;
  std::vector<std::vector<Cell>> rows;

  // Appends a row. Requires row.size() == columns.size() (checked, aborts).
  void AddRow(std::vector<Cell> row);
};

// The text a cell shows, e.g. "12.346", "3.2e-09", "1200", "–". ToHtml shows
// it and ToJson parses it back into the JSON number, so both agree.
std::string FormatCell(const Cell& cell, const Column& column);

struct Paragraph {
  std::string text;     // plain text (escaped on output)
  bool notice = false;  // something missing or wrong: highlighted, and listed in the JSON
};

struct FigureBlock {
  Figure figure;        // drawn by WriteReport into figures/
  std::string title;    // short heading
  std::string caption;  // what is shown, in words a reader needs at a glance
  std::string file;     // figures/<name>.<ext>, set when rendered
};

using Block = std::variant<Paragraph, Table, FigureBlock>;

struct Section {
  std::string id;  // HTML anchor, JSON key
  std::string title;
  std::vector<Block> blocks;  // in page order
};

struct Document {
  std::string kind;           // "run", "experiment", "fit" or "loop"
  std::string title;          // e.g. "Simulation run — paper case 2"
  std::string source;         // the input file as given on the command line
  std::string created;        // ISO 8601 UTC time the report was made
  std::string ccsrm_version;  // of the program that made it
  std::vector<Section> sections;

  std::vector<const Table*> tables() const;
  std::vector<const FigureBlock*> figures() const;
  std::vector<std::string> notices() const;
};

// {"schema": "ccsrm-report/1", "kind", "title", "source", "created",
//  "ccsrm_version", "notices": [...],
//  "sections": [{"id", "title", "tables": [id...], "figures": [file...]}],
//  "tables": {id: {"title", "caption", "columns": [{"key", "header", "unit"}],
//                  "rows": [{key: number | string | null}]}},
//  "figures": [{"file", "title", "caption", "data", "script"}]}
nlohmann::json ToJson(const Document& document);

// A self-contained page: inline style, figures referenced by their relative
// file names, tables with id "table-<id>".
std::string ToHtml(const Document& document);

}  // namespace ccsrm::reports
