// The report's HTML (see html.h).
#include "tools/report/html.h"

#include <cctype>

#include "common/util/atomic_file.h"

namespace pr::cli::report {

std::string escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string urlPath(const std::string& path) {
  static const char* kHex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') out += char(c);
    else out += std::string("%") + kHex[c >> 4] + kHex[c & 15];
  }
  return out;
}

std::string link(const std::string& path, const std::string& text) {
  return "<a href=\"" + escape(urlPath(path)) + "\">" + escape(text) + "</a>";
}

std::string table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                  const std::string& cssClass) {
  std::string out = "<table" + (cssClass.empty() ? std::string() : " class=\"" + cssClass + "\"") + "><thead><tr>";
  for (const std::string& h : header) out += "<th>" + escape(h) + "</th>";
  out += "</tr></thead><tbody>\n";
  for (const auto& row : rows) {
    out += "<tr>";
    for (const std::string& cell : row) out += "<td>" + escape(cell) + "</td>";
    out += "</tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string image(const std::string& src, const std::string& caption) {
  return "<figure class=\"image\"><img src=\"" + escape(urlPath(src)) + "\" alt=\"" + escape(caption) + "\"><figcaption>" +
         escape(caption) + "</figcaption></figure>\n";
}

std::string chart(const std::filesystem::path& dir, const std::string& relDir, const std::string& name,
                  nlohmann::json spec, const nlohmann::json& data, const std::string& caption) {
  writeFileAtomically(dir / (name + ".json"), data.dump(1) + "\n", "chart data file");
  spec["$schema"] = "https://vega.github.io/schema/vega-lite/v5.json";
  spec["data"] = {{"values", data}};
  if (!spec.contains("width")) spec["width"] = 520;
  if (!spec.contains("height")) spec["height"] = 260;
  // No '<' in the inlined JSON (it can only be inside a string there, where \u003c means the
  // same): a "</script" or "<!--" would end or upset the script element.
  std::string text;
  for (char ch : spec.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)) text += ch == '<' ? std::string("\\u003c") : std::string(1, ch);
  const std::string id = relDir + "/" + name;
  return "<figure class=\"chart\"><div class=\"vega\" data-chart=\"" + escape(id) + "\"></div>" +
         "<script type=\"application/json\" class=\"spec\">" + text + "</script><figcaption>" + escape(caption) +
         " " + link(relDir + "/" + name + ".json", "data") + "</figcaption></figure>\n";
}

std::string page(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escape(title) +
         "</title>\n<style>\n"
         "body{font:14px/1.45 system-ui,sans-serif;margin:2em auto;max-width:1400px;padding:0 1em;color:#222}\n"
         "table{border-collapse:collapse;margin:.5em 0 1.5em;font-size:12px}\n"
         "th,td{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#f3f3f3}\n"
         "td:first-child,th:first-child{text-align:left}table.text td,table.text th{text-align:left}\n"
         "figure{display:inline-block;margin:.5em 1em .5em 0;vertical-align:top}\n"
         "figure.image img{image-rendering:pixelated;width:192px;border:1px solid #ccc}\n"
         "figcaption{font-size:12px;color:#555;max-width:600px}\n"
         ".verdict{background:#f6f9ff;border-left:4px solid #4a7;padding:.5em 1em}\n"
         "h2{border-bottom:2px solid #444;margin-top:2em}\n"
         "</style>\n<script src=\"lib/vega.min.js\"></script>\n<script src=\"lib/vega-lite.min.js\"></script>\n"
         "<script src=\"lib/vega-embed.min.js\"></script>\n</head><body>\n" +
         body + "<script src=\"page.js\"></script>\n</body></html>\n";
}

std::string pageScript() {
  return R"(// Embeds every chart of the page and marks on <body> what rendered: data-charts (charts
// drawn), data-chart-total, data-images (images loaded with a size), data-image-total and
// data-errors (script errors, unhandled rejections and console errors), for a person and for
// the report's test.
"use strict";
(function () {
  let errors = 0;
  const body = document.body;
  const mark = () => { body.dataset.errors = String(errors); };
  window.addEventListener("error", () => { errors++; mark(); });
  window.addEventListener("unhandledrejection", () => { errors++; mark(); });
  const consoleError = console.error.bind(console);
  console.error = (...args) => { errors++; mark(); consoleError(...args); };
  mark();
  const charts = Array.from(document.querySelectorAll("figure.chart"));
  body.dataset.chartTotal = String(charts.length);
  let drawn = 0;
  const jobs = charts.map((figure) => {
    try {
      const spec = JSON.parse(figure.querySelector("script.spec").textContent);
      return vegaEmbed(figure.querySelector("div.vega"), spec, { actions: false, renderer: "svg" })
        .then(() => { drawn++; body.dataset.charts = String(drawn); })
        .catch((e) => console.error(e));
    } catch (e) {
      console.error(e);  // one broken chart does not stop the others
      return Promise.resolve();
    }
  });
  const images = Array.from(document.images);
  body.dataset.imageTotal = String(images.length);
  const loaded = images.map((img) => new Promise((resolve) => {
    if (img.complete) resolve(); else { img.addEventListener("load", resolve); img.addEventListener("error", resolve); }
  }));
  Promise.all(loaded).then(() => {
    body.dataset.images = String(images.filter((img) => img.naturalWidth > 0).length);
  });
  Promise.all(jobs).then(() => { body.dataset.charts = String(drawn); body.dataset.done = "1"; });
})();
)";
}

}  // namespace pr::cli::report
