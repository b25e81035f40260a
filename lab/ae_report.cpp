#include "lab/ae_report.hpp"

#include "io/results.hpp"
#include "lab/b_value.hpp"
#include "viz/svg_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace rocklab {

namespace {

nlohmann::json b_value_json(const std::vector<double>& mw) {
  const BValue b = b_value(mw);
  return {{"b", number_or_null(b.b)},
          {"standard_error", number_or_null(b.standard_error)},
          {"completeness_magnitude", number_or_null(b.completeness)},
          {"events_above_completeness", b.events},
          {"events", mw.size()}};
}

} // namespace

nlohmann::json acoustic_emission_summary(const std::vector<FractureEvent>& events,
                                         double peak_time) {
  std::vector<double> all, before;
  std::map<std::string, int> by_class = {{"tensile", 0}, {"shear", 0}, {"implosive", 0}};
  double lo = INFINITY, hi = -INFINITY, m0_sum = 0;
  for (const FractureEvent& e : events) {
    if (!e.has_source || !std::isfinite(e.source.mw))
      continue;
    all.push_back(e.source.mw);
    if (std::isfinite(peak_time) && e.time <= peak_time)
      before.push_back(e.source.mw);
    by_class[to_string(e.source.type)] += 1;
    lo = std::min(lo, e.source.mw), hi = std::max(hi, e.source.mw);
    m0_sum += e.source.m0;
  }
  nlohmann::json j = {
      {"events_with_source", all.size()},
      {"by_source_type", by_class},
      {"moment_magnitude_range", {number_or_null(lo), number_or_null(hi)}},
      {"cumulative_moment_Nm", m0_sum},
      {"b_value", b_value_json(all)},
      {"b_value_before_peak", b_value_json(before)},
      {"methods",
       {{"moment_tensor", "M_ij = sum of dF_i R_j over the contacts of the event's source grains "
                          "with their neighbours (dF the change since the grain joined, R from "
                          "the cracks' centroid), kept at its largest scalar moment (Hazzard & "
                          "Young 2000, 2004)"},
        {"scalar_moment", "M0 = (sum of squared eigenvalues / 2)^(1/2) (Silver & Jordan 1982)"},
        {"moment_magnitude", "Mw = 2/3 log10 M0 - 6, M0 in N m (Hanks & Kanamori 1979)"},
        {"source_type", "R = 100 tr M / (|tr M| + sum |deviatoric eigenvalues|): tensile above "
                        "30, implosive below -30, else shear (Feignier & Young 1992)"},
        {"b_value", "maximum likelihood b = log10 e / (mean M - Mc) over Mw >= Mc (Aki 1965), "
                    "standard error 2.30 b^2 sqrt(sum (M - mean)^2 / (n (n - 1))) (Shi & Bolt "
                    "1982), Mc by maximum curvature of 0.1-wide bins (Wiemer & Wyss 2000); null "
                    "with fewer than 50 events above Mc"}}}};
  return j;
}

void print_acoustic_emission(const nlohmann::json& a) {
  auto b = [](const nlohmann::json& v) {
    char t[96];
    if (v["b"].is_number())
      std::snprintf(t, sizeof t, "%.2f +- %.2f", v["b"].get<double>(),
                    v["standard_error"].get<double>());
    else
      std::snprintf(t, sizeof t, "not measured (%d events above Mc)",
                    v["events_above_completeness"].get<int>());
    return std::string(t);
  };
  const auto& c = a["by_source_type"];
  std::printf("acoustic em. %zu sources: %d tensile, %d shear, %d implosive; b-value %s, before "
              "the peak %s\n",
              a["events_with_source"].get<std::size_t>(), c["tensile"].get<int>(),
              c["shear"].get<int>(), c["implosive"].get<int>(), b(a["b_value"]).c_str(),
              b(a["b_value_before_peak"]).c_str());
}

std::string magnitude_frequency_svg(const std::vector<FractureEvent>& events,
                                    const std::string& title) {
  std::vector<double> mw;
  for (const FractureEvent& e : events)
    if (e.has_source && std::isfinite(e.source.mw))
      mw.push_back(e.source.mw);
  if (mw.empty())
    return "";
  std::sort(mw.begin(), mw.end());
  PlotSeries cum{"events with Mw >= m", {}, {}, "#1f77b4"};
  for (auto it = mw.begin(); it != mw.end(); it = std::upper_bound(it, mw.end(), *it)) {
    cum.x.push_back(*it); // N(M >= m) at each distinct magnitude, counted from its first
    cum.y.push_back(static_cast<double>(mw.end() - it));
  }
  std::map<long, int> bins;
  for (const double m : mw)
    ++bins[static_cast<long>(std::floor(m / kMagnitudeBin))];
  PlotSeries per_bin{"events per 0.1 bin", {}, {}, "#7f7f7f", true};
  for (const auto& [k, n] : bins) {
    per_bin.x.push_back((static_cast<double>(k) + 0.5) * kMagnitudeBin);
    per_bin.y.push_back(n);
  }
  std::vector<PlotSeries> series = {cum, per_bin};
  const BValue b = b_value(mw);
  if (std::isfinite(b.b)) {
    PlotSeries fit{"", {}, {}, "#d62728", true};
    char label[96];
    std::snprintf(label, sizeof label, "b = %.2f +- %.2f (Mc %.1f, %d events)", b.b,
                  b.standard_error, b.completeness, b.events);
    fit.label = label;
    for (const double m : {b.completeness, mw.back()}) {
      fit.x.push_back(m);
      fit.y.push_back(b.events * std::pow(10.0, -b.b * (m - b.completeness)));
    }
    series.push_back(fit);
  }
  return line_plot_svg(title, "moment magnitude Mw [-]", "number of events [-]", "", series, {},
                       NAN, true);
}

std::string acoustic_emission_svg(const LoadCurve& c, const std::vector<FractureEvent>& events,
                                  const std::string& title) {
  std::vector<std::pair<double, double>> at; // (axial strain %, M0) of each event with a source
  for (const FractureEvent& e : events) {
    if (!e.has_source)
      continue;
    const auto k = static_cast<std::size_t>(std::lower_bound(c.time.begin(), c.time.end(), e.time) -
                                            c.time.begin());
    if (k < c.time.size())
      at.emplace_back(c.strain_pct[k], e.source.m0);
  }
  if (at.empty())
    return "";
  std::sort(at.begin(), at.end());
  PlotSeries curve{c.label, c.strain_pct, c.stress_mpa, "#000000"};
  double m0_total = 0;
  for (const auto& [x, m0] : at)
    m0_total += m0;
  PlotSeries count{"events (cumulative)", {}, {}, "#1f77b4", false, true};
  PlotSeries moment{"moment M0 (cumulative)", {}, {}, "#d62728", false, true};
  double m0_sum = 0;
  for (std::size_t i = 0; i < at.size(); ++i) {
    m0_sum += at[i].second;
    count.x.push_back(at[i].first),
        count.y.push_back(100.0 * static_cast<double>(i + 1) / static_cast<double>(at.size()));
    moment.x.push_back(at[i].first), moment.y.push_back(100 * m0_sum / m0_total);
  }
  constexpr int kBins = 50;
  const double x0 = c.strain_pct.front(), x1 = std::max(c.strain_pct.back(), x0 + 1e-12);
  std::vector<int> bins(kBins, 0);
  for (const auto& [x, m0] : at)
    ++bins[static_cast<std::size_t>(
        std::clamp(static_cast<int>(kBins * (x - x0) / (x1 - x0)), 0, kBins - 1))];
  const int most = *std::max_element(bins.begin(), bins.end());
  PlotSeries rate{"event rate (per 1/50 of the strain range)", {}, {}, "#7f7f7f", true, true};
  for (int k = 0; k < kBins; ++k) {
    rate.x.push_back(x0 + (k + 0.5) * (x1 - x0) / kBins);
    rate.y.push_back(100.0 * bins[static_cast<std::size_t>(k)] / most);
  }
  return line_plot_svg(title + ", acoustic emission", c.xlabel, c.ylabel,
                       "events and moment, cumulative; rate as share of its busiest bin [%]",
                       {curve, rate, count, moment});
}

} // namespace rocklab
