// The page as data: one Document gives both index.html and summary.json,
// and their numbers agree to the digit.
#include "ccsrm/reports/document.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "report_test_util.h"

namespace ccsrm::reports {
namespace {
using ::testing::HasSubstr;

TEST(FormatCell, ShowsNumbersAsTheColumnSays) {
  const Column fixed{"v", "v", "deg", NumberFormat::Fixed(3)};
  const Column sig{"v", "v", "", NumberFormat::Significant(3)};
  const Column integer{"v", "v", "", NumberFormat::Integer()};
  EXPECT_EQ(FormatCell(Cell::Number(6.0004), fixed), "6.000");
  EXPECT_EQ(FormatCell(Cell::Number(-0.0001), fixed), "0.000");  // no "-0.000"
  EXPECT_EQ(FormatCell(Cell::Number(3.21e-9), sig), "3.21e-09");
  EXPECT_EQ(FormatCell(Cell::Number(1234.0), integer), "1234");
  EXPECT_EQ(FormatCell(Cell::Number(NAN), fixed), "–");
  EXPECT_EQ(FormatCell(Cell::Missing(), fixed), "–");
  EXPECT_EQ(FormatCell(Cell::Text("joint 1"), fixed), "joint 1");
  // A cell's own format wins over its column's (key-value tables).
  EXPECT_EQ(FormatCell(Cell::Number(12.0, NumberFormat::Integer()), fixed), "12");
}

Document Sample() {
  Table table;
  table.id = "sample";
  table.title = "A <sample> & more";
  table.columns = {{"name", "name", "", NumberFormat::Integer()},
                   {"angle_deg", "θx", "deg", NumberFormat::Fixed(3)},
                   {"count", "count", "", NumberFormat::Integer()}};
  table.AddRow({Cell::Text("a&b"), Cell::Number(M_PI), Cell::Number(7)});
  table.AddRow({Cell::Text("c"), Cell::Number(NAN), Cell::Number(-3)});
  Figure figure;
  figure.name = "fig";
  figure.panels.push_back(Panel{});
  Document document;
  document.kind = "run";
  document.title = "Test";
  document.source = "run.h5";
  document.sections.push_back(
      Section{"one",
              "One",
              {Paragraph{"plain", false}, Paragraph{"something is missing", true}, table,
               FigureBlock{figure, "A figure", "caption", "figures/fig.png"}}});
  return document;
}

TEST(Document, JsonHoldsTheNumbersThePageShows) {
  const Document document = Sample();
  const nlohmann::json json = ToJson(document);
  EXPECT_EQ(json["schema"], kReportSchema);
  const nlohmann::json& rows = json["tables"]["sample"]["rows"];
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0]["angle_deg"].get<double>(), 3.142);  // as shown, not 3.14159...
  EXPECT_TRUE(rows[0]["count"].is_number_integer());
  EXPECT_TRUE(rows[1]["angle_deg"].is_null());
  EXPECT_EQ(rows[0]["name"], "a&b");
  EXPECT_EQ(json["notices"], nlohmann::json::array({"something is missing"}));
  EXPECT_EQ(json["figures"][0]["file"], "figures/fig.png");
  EXPECT_EQ(json["figures"][0]["data"], "figures/fig.dat");

  const std::string html = ToHtml(document);
  EXPECT_THAT(html, HasSubstr("A &lt;sample&gt; &amp; more"));
  EXPECT_THAT(html, HasSubstr("<th>θx [deg]</th>"));
  EXPECT_THAT(html, HasSubstr("<p class=\"notice\">something is missing</p>"));
  EXPECT_THAT(html, HasSubstr("<img src=\"figures/fig.png\""));
  EXPECT_EQ(testing::ExpectTablesMatchJson(html, json), 3);
}

}  // namespace
}  // namespace ccsrm::reports
