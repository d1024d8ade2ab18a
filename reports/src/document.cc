#include "ccsrm/reports/document.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "ccsrm/common/error.h"

namespace ccsrm::reports {
namespace {

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string HeaderText(const Column& column) {
  return column.unit.empty() ? column.header : column.header + " [" + column.unit + "]";
}

// The page's look: one place, no external files.
constexpr const char* kStyle = R"(
body { font-family: "DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif; color: #222;
       margin: 0; background: #f4f5f7; font-size: 15px; line-height: 1.45; }
main { max-width: 1400px; margin: 0 auto; padding: 24px 32px 64px; background: #fff; }
header h1 { font-size: 26px; margin: 0 0 6px; }
header .meta { color: #555; font-size: 13px; }
header .meta code { background: #f0f0f0; padding: 1px 4px; border-radius: 3px;
                   overflow-wrap: anywhere; }
nav { margin: 16px 0 8px; padding: 8px 12px; background: #f7f7f9; border: 1px solid #e3e3e8;
      border-radius: 6px; font-size: 14px; display: flex; flex-wrap: wrap; gap: 4px 16px; }
nav a { color: #1f5fa8; text-decoration: none; white-space: nowrap; }
nav a:hover { text-decoration: underline; }
section { margin-top: 32px; border-top: 1px solid #e3e3e8; padding-top: 8px; }
h2 { font-size: 21px; margin: 12px 0 10px; }
h3 { font-size: 16px; margin: 18px 0 6px; }
p { margin: 6px 0 10px; max-width: 80em; }
p.notice { background: #fff6db; border-left: 4px solid #e0a800; padding: 6px 10px; }
.tables { display: flex; flex-wrap: wrap; gap: 8px 48px; align-items: flex-start; }
.table-block { width: fit-content; min-width: 360px; max-width: 100%; }
.table-block .caption { contain: inline-size; }
.table-wrap { overflow-x: auto; margin: 6px 0 4px; }
table { border-collapse: collapse; font-size: 13.5px; }
th, td { padding: 3px 10px; border-bottom: 1px solid #e6e6ea; text-align: left; }
td { white-space: nowrap; }
th { background: #eef0f4; font-weight: 600; vertical-align: bottom; min-width: 3.5em; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.wrap { white-space: normal; overflow-wrap: break-word; min-width: 9em; max-width: 36em; }
tbody tr:nth-child(even) { background: #fafafc; }
.caption { color: #555; font-size: 13px; margin: 2px 0 14px; }
figure { margin: 10px 0 18px; }
figure img { max-width: 100%; height: auto; border: 1px solid #e6e6ea; }
figcaption { color: #444; font-size: 13.5px; margin-top: 4px; max-width: 80em; }
)";

// Escaped text that may wrap inside the names it holds: a <wbr> after each
// '/', '_', '@' and '=' and each '.' before a letter (a file path, plan or
// parameter name; not a number's decimal point), so that a column of them
// can be narrower than its longest name without cutting a word anywhere
// else, and without characters a copied name would carry.
std::string Breakable(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    out += Escape(std::string(1, c));
    const bool letter_next =
        i + 1 < text.size() && std::isalpha(static_cast<unsigned char>(text[i + 1]));
    if (c == '/' || c == '_' || c == '@' || c == '=' || (c == '.' && letter_next)) out += "<wbr>";
  }
  return out;
}

void WriteTable(const Table& table, std::ostream& out) {
  out << "<div class=\"table-block\">\n<h3>" << Escape(table.title)
      << "</h3>\n<div class=\"table-wrap\"><table id=\"table-" << Escape(table.id)
      << "\">\n<thead><tr>";
  for (const Column& column : table.columns) out << "<th>" << Escape(HeaderText(column)) << "</th>";
  out << "</tr></thead>\n<tbody>\n";
  for (const auto& row : table.rows) {
    out << "<tr>";
    for (std::size_t i = 0; i < row.size(); ++i) {
      const bool number = row[i].kind != Cell::Kind::kText;
      out << (number                  ? "<td class=\"num\">"
              : table.columns[i].wrap ? "<td class=\"wrap\">"
                                      : "<td>")
          << (table.columns[i].wrap ? Breakable(FormatCell(row[i], table.columns[i]))
                                    : Escape(FormatCell(row[i], table.columns[i])))
          << "</td>";
    }
    out << "</tr>\n";
  }
  out << "</tbody></table></div>\n";
  if (!table.caption.empty()) out << "<p class=\"caption\">" << Escape(table.caption) << "</p>\n";
  out << "</div>\n";
}

void WriteFigure(const FigureBlock& block, std::ostream& out) {
  out << "<figure id=\"figure-" << Escape(block.figure.name) << "\">\n";
  if (!block.title.empty()) out << "<h3>" << Escape(block.title) << "</h3>\n";
  const int width = block.figure.panel_width_px * block.figure.columns;
  out << "<img src=\"" << Escape(block.file) << "\" alt=\"" << Escape(block.title) << "\" width=\""
      << width << "\">\n";
  if (!block.caption.empty()) out << "<figcaption>" << Escape(block.caption) << "</figcaption>\n";
  out << "</figure>\n";
}

nlohmann::json CellJson(const Cell& cell, const Column& column) {
  switch (cell.kind) {
    case Cell::Kind::kText:
      return cell.text;
    case Cell::Kind::kMissing:
      return nullptr;
    case Cell::Kind::kNumber:
      break;
  }
  const std::string shown = FormatCell(cell, column);
  const NumberFormat format = cell.has_format ? cell.format : column.format;
  if (format.kind == NumberFormat::Kind::kInteger) return std::stoll(shown);
  return std::stod(shown);
}

}  // namespace

Cell Cell::Text(std::string text) {
  Cell cell;
  cell.kind = Kind::kText;
  cell.text = std::move(text);
  return cell;
}

Cell Cell::Number(double value) {
  Cell cell;
  if (!std::isfinite(value)) return cell;
  cell.kind = Kind::kNumber;
  cell.number = value;
  return cell;
}

Cell Cell::Number(double value, NumberFormat format) {
  Cell cell = Number(value);
  cell.has_format = true;
  cell.format = format;
  return cell;
}

void Table::AddRow(std::vector<Cell> row) {
  CCSRM_CHECK(row.size() == columns.size());
  rows.push_back(std::move(row));
}

std::string FormatCell(const Cell& cell, const Column& column) {
  switch (cell.kind) {
    case Cell::Kind::kText:
      return cell.text;
    case Cell::Kind::kMissing:
      return "–";
    case Cell::Kind::kNumber:
      break;
  }
  const NumberFormat format = cell.has_format ? cell.format : column.format;
  char text[64];
  switch (format.kind) {
    case NumberFormat::Kind::kFixed:
      std::snprintf(text, sizeof(text), "%.*f", format.digits, cell.number);
      break;
    case NumberFormat::Kind::kSignificant:
      std::snprintf(text, sizeof(text), "%.*g", format.digits, cell.number);
      break;
    case NumberFormat::Kind::kInteger:
      std::snprintf(text, sizeof(text), "%.0f", cell.number);
      break;
  }
  std::string shown = text;
  // A value that rounds to zero is shown as 0, not -0.
  if (shown[0] == '-' && std::stod(shown) == 0.0) shown.erase(0, 1);
  return shown;
}

std::vector<const Table*> Document::tables() const {
  std::vector<const Table*> out;
  for (const Section& section : sections) {
    for (const Block& block : section.blocks) {
      if (const auto* table = std::get_if<Table>(&block)) out.push_back(table);
    }
  }
  return out;
}

std::vector<const FigureBlock*> Document::figures() const {
  std::vector<const FigureBlock*> out;
  for (const Section& section : sections) {
    for (const Block& block : section.blocks) {
      if (const auto* figure = std::get_if<FigureBlock>(&block)) out.push_back(figure);
    }
  }
  return out;
}

std::vector<std::string> Document::notices() const {
  std::vector<std::string> out;
  for (const Section& section : sections) {
    for (const Block& block : section.blocks) {
      const auto* paragraph = std::get_if<Paragraph>(&block);
      if (paragraph && paragraph->notice) out.push_back(paragraph->text);
    }
  }
  return out;
}

nlohmann::json ToJson(const Document& document) {
  nlohmann::json json;
  json["schema"] = kReportSchema;
  json["kind"] = document.kind;
  json["title"] = document.title;
  json["source"] = document.source;
  json["created"] = document.created;
  json["ccsrm_version"] = document.ccsrm_version;
  json["notices"] = document.notices();
  json["sections"] = nlohmann::json::array();
  json["tables"] = nlohmann::json::object();
  json["figures"] = nlohmann::json::array();
  for (const Section& section : document.sections) {
    nlohmann::json entry = {{"id", section.id},
                            {"title", section.title},
                            {"tables", nlohmann::json::array()},
                            {"figures", nlohmann::json::array()}};
    for (const Block& block : section.blocks) {
      if (const auto* table = std::get_if<Table>(&block)) {
        entry["tables"].push_back(table->id);
        nlohmann::json t = {{"title", table->title}, {"caption", table->caption}};
        t["columns"] = nlohmann::json::array();
        for (const Column& column : table->columns) {
          t["columns"].push_back(
              {{"key", column.key}, {"header", column.header}, {"unit", column.unit}});
        }
        t["rows"] = nlohmann::json::array();
        for (const auto& row : table->rows) {
          nlohmann::json r = nlohmann::json::object();
          for (std::size_t i = 0; i < row.size(); ++i) {
            r[table->columns[i].key] = CellJson(row[i], table->columns[i]);
          }
          t["rows"].push_back(std::move(r));
        }
        json["tables"][table->id] = std::move(t);
      } else if (const auto* figure = std::get_if<FigureBlock>(&block)) {
        entry["figures"].push_back(figure->file);
        json["figures"].push_back({{"file", figure->file},
                                   {"title", figure->title},
                                   {"caption", figure->caption},
                                   {"data", "figures/" + figure->figure.name + ".dat"},
                                   {"script", "figures/" + figure->figure.name + ".gp"}});
      }
    }
    json["sections"].push_back(std::move(entry));
  }
  return json;
}

std::string ToHtml(const Document& document) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      << "<title>" << Escape(document.title) << "</title>\n<style>" << kStyle
      << "</style>\n</head>\n<body>\n<main>\n<header>\n<h1>" << Escape(document.title)
      << "</h1>\n<div class=\"meta\">input <code>" << Escape(document.source)
      << "</code> · report made " << Escape(document.created) << " by ccsrm "
      << Escape(document.ccsrm_version)
      << " · every number on this page is also in <a href=\"summary.json\">summary.json</a>"
      << "</div>\n</header>\n<nav>";
  for (const Section& section : document.sections) {
    out << "<a href=\"#" << Escape(section.id) << "\">" << Escape(section.title) << "</a>";
  }
  out << "</nav>\n";
  for (const Section& section : document.sections) {
    out << "<section id=\"" << Escape(section.id) << "\">\n<h2>" << Escape(section.title)
        << "</h2>\n";
    // Consecutive tables share a row while the page is wide enough.
    bool in_row = false;
    for (const Block& block : section.blocks) {
      const auto* table = std::get_if<Table>(&block);
      if (table != nullptr && !in_row) out << "<div class=\"tables\">\n";
      if (table == nullptr && in_row) out << "</div>\n";
      in_row = table != nullptr;
      if (const auto* paragraph = std::get_if<Paragraph>(&block)) {
        out << (paragraph->notice ? "<p class=\"notice\">" : "<p>") << Escape(paragraph->text)
            << "</p>\n";
      } else if (table != nullptr) {
        WriteTable(*table, out);
      } else {
        WriteFigure(std::get<FigureBlock>(block), out);
      }
    }
    if (in_row) out << "</div>\n";
    out << "</section>\n";
  }
  out << "</main>\n</body>\n</html>\n";
  return out.str();
}

}  // namespace ccsrm::reports
