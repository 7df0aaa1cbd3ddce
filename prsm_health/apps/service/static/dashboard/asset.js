// One asset (/assets/{asset_id}): its latest diagnosis and prognosis (GET
// /v1/assets/{asset_id}?prognosis=true), the clearance and class probabilities over time or
// operating hours (GET /v1/assets/{asset_id}/history) and the spectra of its latest window
// (GET /v1/assets/{asset_id}/spectra), with the defect frequencies marked.
"use strict";

PH.ready(async () => {
  const id = document.body.dataset.assetId;
  const base = "/v1/assets/" + encodeURIComponent(id);
  const status = document.getElementById("status");
  try {
    const [summary, history] = await Promise.all([
      PH.getJSON(base + "?prognosis=true"),
      PH.getJSON(base + "/history?limit=1000"),
    ]);
    showLatest(summary.latest);
    showPrognosis(summary.prognosis);
    const axis = xAxis(history.diagnoses);
    clearancePlot(axis, summary.prognosis);
    classPlot(axis);
    if (summary.spectra_received_at) {
      showSpectra(await PH.getJSON(base + "/spectra"), summary);
    } else {
      document.getElementById("spectra").hidden = true;
      document.getElementById("spectra-note").textContent =
        "No spectra stored for this asset: none of its recordings had the nut axial " +
        "acceleration channel (nut_axial_accel).";
    }
    status.textContent = history.truncated
      ? `${summary.diagnoses} diagnoses stored; the plots show the latest ${history.count}.`
      : `${summary.diagnoses} diagnoses stored.`;
  } catch (error) {
    status.textContent = error.status === 404
      ? `No diagnosis is stored for asset ${id}.`
      : "Could not load the asset: " + error.message;
    status.classList.add("error");
  }
});

function source(item) {
  return item.filename ? `${item.source}: ${item.filename}` : item.source;
}

function showLatest(latest) {
  const span = latest.window
    ? ` (window ${latest.window.index}, ${latest.window.start.toFixed(3)} – ${latest.window.end.toFixed(3)} s)`
    : "";
  const model = latest.model ? `${latest.model.name} ${latest.model.version} (${latest.model.design})` : "–";
  PH.define(document.getElementById("latest"), [
    ["Fault class (probability)", PH.classText(latest)],
    ["Clearance [µm] (90 % interval)", PH.clearanceText(latest.clearance)],
    ["Operating hours [h]", PH.hours(latest.operating_hours)],
    ["Received (UTC)", PH.time(latest.received_at)],
    ["Recording", source(latest) + span],
    ["Model", model],
  ]);
  PH.fill(document.getElementById("warnings"), latest.warnings || []);
}

function showPrognosis(prognosis) {
  const rul = document.getElementById("rul");
  const detail = document.getElementById("rul-detail");
  if (prognosis && prognosis.rul_hours) {
    rul.textContent = PH.rulText(prognosis.rul_hours) + " h";
    detail.textContent = `Median and 90 % interval (${prognosis.method}); failure threshold ` +
      `${PH.um(prognosis.threshold)} µm, latest clearance ${PH.um(prognosis.current)} µm.`;
    PH.fill(document.getElementById("rul-warnings"), prognosis.warnings || []);
  } else {
    rul.textContent = "–";
    detail.textContent = prognosis && prognosis.error ? prognosis.error : "No prognosis.";
  }
}

// Over operating hours when at least two diagnoses have them, else over receive time.
function xAxis(entries) {
  const withHours = entries.filter((e) => PH.finite(e.operating_hours));
  const note = document.getElementById("trend-note");
  if (withHours.length >= 2) {
    const rows = withHours.slice().sort((a, b) => a.operating_hours - b.operating_hours);
    const left = entries.length - rows.length;
    note.textContent = "Over operating hours" +
      (left ? `; ${left} diagnosis(es) sent without operating hours are not shown.` : ".");
    return {rows, xs: rows.map((e) => e.operating_hours), time: false, label: "operating hours [h]"};
  }
  note.textContent = "Over receive time (fewer than two diagnoses have operating hours).";
  return {rows: entries, xs: entries.map((e) => Date.parse(e.received_at) / 1000), time: true,
    label: "received (UTC)"};
}

function axisOptions(axis, yLabel) {
  const options = {
    scales: {x: {time: axis.time}},
    axes: [{label: axis.label}, {label: yLabel}],
    legend: {live: true},
  };
  if (axis.time) options.tzDate = (ts) => uPlot.tzDate(new Date(ts * 1e3), "Etc/UTC");
  return options;
}

function clearancePlot(axis, prognosis) {
  const value = (v) => (PH.finite(v) ? v * 1e6 : null);
  const clearance = (e) => e.diagnosis.clearance || {};
  const data = [
    axis.xs,
    axis.rows.map((e) => value(clearance(e).estimate)),
    axis.rows.map((e) => value(clearance(e).lower)),
    axis.rows.map((e) => value(clearance(e).upper)),
  ];
  const blue = PH.palette[0];
  const series = [
    {label: axis.label},
    {label: "clearance [µm]", stroke: blue, width: 2, points: {show: true, size: 6}},
    {label: "90 % lower", stroke: "rgba(31,119,180,0.6)", dash: [4, 4]},
    {label: "90 % upper", stroke: "rgba(31,119,180,0.6)", dash: [4, 4]},
  ];
  if (prognosis && PH.finite(prognosis.threshold)) {
    data.push(axis.xs.map(() => prognosis.threshold * 1e6));
    series.push({label: "failure threshold [µm]", stroke: PH.palette[1], dash: [10, 5]});
  }
  const options = Object.assign(axisOptions(axis, "clearance [µm]"), {
    series,
    bands: [{series: [3, 2], fill: "rgba(31,119,180,0.15)"}],
  });
  PH.plot(document.getElementById("clearance-plot"), options, data);
}

function classPlot(axis) {
  const names = [...new Set(axis.rows.flatMap((e) => Object.keys(e.diagnosis.class_probabilities || {})))].sort();
  const data = [axis.xs];
  const series = [{label: axis.label}];
  names.forEach((name, i) => {
    data.push(axis.rows.map((e) => {
      const p = (e.diagnosis.class_probabilities || {})[name];
      return PH.finite(p) ? p : null;
    }));
    series.push({label: name, stroke: PH.palette[i % PH.palette.length], width: 1.5,
      points: {show: true, size: 5}});
  });
  const options = Object.assign(axisOptions(axis, "probability"), {series});
  options.scales.y = {range: [0, 1]};
  PH.plot(document.getElementById("class-plot"), options, data);
}

// One marker per distinct frequency (several defects can share one: nut flank and ring-gear
// tooth both pass at n_r·f_c).
function markerLines(frequencies) {
  const groups = [];
  const sorted = Object.entries(frequencies).filter(([, f]) => PH.finite(f) && f > 0)
    .sort((a, b) => a[1] - b[1]);
  for (const [name, f] of sorted) {
    const same = groups.find((g) => Math.abs(g.x - f) <= 1e-6 * f);
    if (same) same.names.push(name);
    else groups.push({x: f, names: [name]});
  }
  return groups.map((g, i) => ({
    x: g.x,
    label: `${g.names.join(" = ")} ${g.x.toFixed(1)} Hz`,
    color: g.names.includes("gear_mesh") ? "#d62728" : PH.palette[(i + 2) % PH.palette.length],
  }));
}

function showSpectra(spectra, summary) {
  const w = spectra.window;
  const where = w ? `window ${w.index} (${w.start.toFixed(3)} – ${w.end.toFixed(3)} s) of the ` : "";
  const speed = PH.finite(spectra.screw_speed) ? `${spectra.screw_speed.toFixed(1)} rad/s` : "unknown";
  let text = `Last ${where}recording received ${PH.time(spectra.received_at)} UTC ` +
    `(${source(spectra)}): ${spectra.samples} samples at ${spectra.sample_rate} Hz, mean screw ` +
    `speed ${speed}. Dashed lines: the defect frequencies at that speed.`;
  if (spectra.received_at < summary.last_received_at) {
    text += " Later recordings had no nut axial acceleration: these are the latest spectra stored.";
  }
  document.getElementById("spectra-note").textContent = text;
  const lines = markerLines(spectra.frequencies);
  const positive = (values) => values.map((v) => (v > 0 ? v : null));
  PH.plot(document.getElementById("spectrum-plot"), {
    scales: {x: {time: false, distr: 3}, y: {distr: 3}},
    series: [{label: "frequency [Hz]"}, {label: "amplitude [m/s²]", stroke: PH.palette[0], width: 1}],
    axes: [{label: "frequency [Hz]"}, {label: "amplitude [m/s²]"}],
    plugins: [PH.markers(lines)],
  }, [spectra.spectrum.frequency, positive(spectra.spectrum.amplitude)]);

  const envelope = spectra.envelope;
  const envelopeNote = document.getElementById("envelope-note");
  if (envelope) {
    // first shown up to a little above the highest marked frequency (the whole spectrum,
    // up to the band's modulation limit, on a double click)
    const highest = Math.max(0, ...lines.map((line) => line.x));
    const shown = highest > 0 ? Math.min(envelope.modulation_limit, 1.25 * highest) : envelope.modulation_limit;
    envelopeNote.textContent = `Envelope of the band ${envelope.band[0].toFixed(0)} – ` +
      `${envelope.band[1].toFixed(0)} Hz, chosen by spectral kurtosis (SK ${envelope.sk.toFixed(2)}, ` +
      `${envelope.impulsive ? "impulsive" : "not above the noise threshold"}); computed up to ` +
      `${envelope.modulation_limit.toFixed(0)} Hz, the highest modulation the band carries ` +
      `(shown to ${shown.toFixed(0)} Hz: drag to zoom, double-click for all).`;
    PH.plot(document.getElementById("envelope-plot"), {
      scales: {x: {time: false}},
      series: [{label: "frequency [Hz]"}, {label: "envelope amplitude [m/s²]", stroke: PH.palette[3], width: 1}],
      axes: [{label: "frequency [Hz]"}, {label: "envelope amplitude [m/s²]"}],
      plugins: [PH.markers(lines)],
      hooks: {ready: [(u) => u.setScale("x", {min: 0, max: shown})]},
    }, [envelope.frequency, envelope.amplitude]);
  } else {
    envelopeNote.textContent = "No envelope spectrum: " + (spectra.envelope_note || "no band fits.");
    document.getElementById("envelope-plot").hidden = true;
  }

  const fmt = (v, digits) => (PH.finite(v) ? v.toPrecision(digits) : "–");
  const rows = Object.entries(spectra.frequencies).map(([name, f]) => {
    const line = (spectra.lines || {})[name] || {};
    const row = PH.el("tr");
    row.append(PH.el("th", name, {scope: "row"}), PH.el("td", f.toFixed(2), {class: "num"}),
      PH.el("td", fmt(line.amplitude, 3), {class: "num"}), PH.el("td", fmt(line.ratio, 3), {class: "num"}));
    return row;
  });
  document.querySelector("#defects tbody").replaceChildren(...rows);
}
