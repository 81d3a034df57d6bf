// The report's HTML: escaping, tables, images and charts. A chart is a Vega-Lite spec whose
// data is inlined (a page opened from disk may not fetch files beside it) and also written
// beside the page as JSON, linked under the chart; page.js embeds every chart and marks on
// <body> how many rendered, how many images loaded and how many script errors happened.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pr::cli::report {

std::string escape(const std::string& text);
// A relative path as a URL: every byte but letters, digits, '-', '.', '_', '~' and '/'
// percent-encoded (a '#', '?' or '%' in a scene's name would otherwise break the link).
std::string urlPath(const std::string& path);
// A link to a file of the report: href escaped and encoded.
std::string link(const std::string& path, const std::string& text);

// A table: header cells then rows, every cell escaped.
std::string table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                  const std::string& cssClass = "");

// A figure with an image file (relative to the page) and its caption.
std::string image(const std::string& src, const std::string& caption);

// A chart: writes `data` to dir/<name>.json and returns the chart's markup with the spec
// (its data.values set to `data`) inlined. `relDir` is dir as the page links it.
std::string chart(const std::filesystem::path& dir, const std::string& relDir, const std::string& name,
                  nlohmann::json spec, const nlohmann::json& data, const std::string& caption);

// The whole page around the sections: title, style, the script libraries from lib/ and page.js.
std::string page(const std::string& title, const std::string& body);

// The page script (written as page.js beside index.html).
std::string pageScript();

}  // namespace pr::cli::report
