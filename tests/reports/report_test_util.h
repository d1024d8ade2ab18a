#pragma once
// Reading a report back the way a user's tools would: the tables of
// index.html (by their ids), the files it references, and a check that
// every table cell equals its value in summary.json.
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ccsrm::reports::testing {

using HtmlTable = std::vector<std::vector<std::string>>;  // rows of cell texts

// A cell's text as a reader sees it: entities decoded, the <wbr> break
// opportunities of a wrapping column (document.cc, Breakable) dropped.
inline std::string Unescape(std::string text) {
  for (std::size_t at = text.find("<wbr>"); at != std::string::npos; at = text.find("<wbr>", at)) {
    text.erase(at, 5);
  }
  const std::pair<const char*, const char*> entities[] = {
      {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&amp;", "&"}};
  for (const auto& [entity, plain] : entities) {
    for (std::size_t at = text.find(entity); at != std::string::npos;
         at = text.find(entity, at + 1)) {
      text.replace(at, std::string(entity).size(), plain);
    }
  }
  return text;
}

// The body cells (<td>) of every <table id="table-<id>">, by id.
inline std::map<std::string, HtmlTable> HtmlTables(const std::string& html) {
  std::map<std::string, HtmlTable> tables;
  const std::string open = "<table id=\"table-";
  for (std::size_t at = html.find(open); at != std::string::npos; at = html.find(open, at + 1)) {
    const std::size_t id_end = html.find('"', at + open.size());
    const std::string id = html.substr(at + open.size(), id_end - at - open.size());
    const std::size_t end = html.find("</table>", id_end);
    const std::string body = html.substr(id_end, end - id_end);
    HtmlTable& rows = tables[id];
    for (std::size_t r = body.find("<tr>"); r != std::string::npos; r = body.find("<tr>", r + 1)) {
      const std::size_t r_end = body.find("</tr>", r);
      const std::string row = body.substr(r, r_end - r);
      if (row.find("<td") == std::string::npos) continue;  // the header row
      std::vector<std::string> cells;
      for (std::size_t c = row.find("<td"); c != std::string::npos; c = row.find("<td", c + 1)) {
        const std::size_t text = row.find('>', c) + 1;
        cells.push_back(Unescape(row.substr(text, row.find("</td>", text) - text)));
      }
      rows.push_back(cells);
    }
  }
  return tables;
}

// Every src="..." and href="..." of the page.
inline std::vector<std::string> HtmlReferences(const std::string& html) {
  std::vector<std::string> refs;
  for (const std::string attribute : {" src=\"", " href=\""}) {
    for (std::size_t at = html.find(attribute); at != std::string::npos;
         at = html.find(attribute, at + 1)) {
      const std::size_t begin = at + attribute.size();
      refs.push_back(Unescape(html.substr(begin, html.find('"', begin) - begin)));
    }
  }
  return refs;
}

// Each HTML table has a JSON twin with the same rows: a number shown on the
// page parses to exactly the JSON number, a text is the JSON string, "–" is
// null. Returns the number of numeric cells compared.
inline int ExpectTablesMatchJson(const std::string& html, const nlohmann::json& summary) {
  const std::map<std::string, HtmlTable> tables = HtmlTables(html);
  EXPECT_EQ(tables.size(), summary.at("tables").size());
  int numbers = 0;
  for (const auto& [id, rows] : tables) {
    SCOPED_TRACE("table " + id);
    const nlohmann::json& table = summary.at("tables").at(id);
    const nlohmann::json& columns = table.at("columns");
    const nlohmann::json& json_rows = table.at("rows");
    EXPECT_EQ(rows.size(), json_rows.size());
    for (std::size_t r = 0; r < std::min(rows.size(), json_rows.size()); ++r) {
      EXPECT_EQ(rows[r].size(), columns.size());
      for (std::size_t c = 0; c < std::min(rows[r].size(), columns.size()); ++c) {
        const std::string& shown = rows[r][c];
        const nlohmann::json& value = json_rows[r].at(columns[c].at("key").get<std::string>());
        SCOPED_TRACE("row " + std::to_string(r) + ", column " + columns[c].at("key").dump() +
                     ": page '" + shown + "', json " + value.dump());
        if (value.is_null()) {
          EXPECT_EQ(shown, "–");
        } else if (value.is_string()) {
          EXPECT_EQ(shown, value.get<std::string>());
        } else {
          EXPECT_TRUE(value.is_number());
          if (!value.is_number()) continue;
          EXPECT_EQ(std::stod(shown), value.get<double>());
          ++numbers;
        }
      }
    }
  }
  return numbers;
}

inline bool ProgramOnPath(const std::string& name) {
  return std::system(("command -v " + name + " >/dev/null 2>&1").c_str()) == 0;
}

}  // namespace ccsrm::reports::testing
