// One asset (/assets/{asset_id}): its latest diagnosis, prognosis, baseline and evidence (GET
// /v1/assets/{asset_id}?prognosis=true), the evidence after each recording (GET
// /v1/assets/{asset_id}/evidence), the clearance and class probabilities over time or
// operating hours (GET /v1/assets/{asset_id}/history) and the spectra of its latest window
// (GET /v1/assets/{asset_id}/spectra), with the defect frequencies marked; when the latest
// recording is a health check, its phases with their readings and verdicts (latest.check).
"use strict";

PH.ready(async () => {
  const id = document.body.dataset.assetId;
  const base = "/v1/assets/" + encodeURIComponent(id);
  const status = document.getElementById("status");
  try {
    // the summary first: an unknown asset is one 404, not three
    const summary = await PH.getJSON(base + "?prognosis=true");
    const [history, evidence] = await Promise.all([
      PH.getJSON(base + "/history?limit=1000"),
      PH.getJSON(base + "/evidence?limit=1000"),
    ]);
    showLatest(summary.latest);
    showCheck(summary.latest, summary.status);
    showPrognosis(summary.prognosis);
    showEvidence(summary, evidence);
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
    ["Fault class (probability)", PH.classText(latest), PH.observableClass(latest, "fault")],
    ["Clearance [µm] (90 % interval)", PH.clearanceText(latest), PH.observableClass(latest, "clearance")],
    ["Operating hours [h]", PH.hours(latest.operating_hours)],
    ["Received (UTC)", PH.time(latest.received_at)],
    ["Recording", source(latest) + span],
    ["Model", model],
  ]);
  PH.fill(document.getElementById("warnings"), latest.warnings || []);
}

// ---------------------------------------------------------------- the latest health check
function readingText(r) {
  const name = r.name.replace(/^check_/, "");
  if (!PH.finite(r.value)) return `${name}: not read`;
  const [factor, unit] = r.unit === "m" ? [1e6, "µm"] : [1, r.unit === "-" ? "" : r.unit];
  const z = PH.finite(r.z) ? ` (z ${r.z >= 0 ? "+" : ""}${r.z.toFixed(1)})` : "";
  return `${name} = ${(factor * r.value).toPrecision(4)} ${unit}`.trimEnd() + z;
}

function showCheck(latest, status) {
  const check = latest.check;
  if (!check) return;  // the latest recording is no health check
  document.getElementById("check").hidden = false;
  document.getElementById("check-note").textContent = "Each role of the check read in the " +
    "phase whose commanded condition brings it out (found by its condition, not its name); " +
    "the z-scores are against the asset's own baseline once it is complete. Asset status: " +
    `${status ? status.level : "–"}.`;
  const rows = check.map((v) => {
    const row = PH.el("tr");
    const verdict = v.phase === null ? `not read: the check has no ${v.condition}`
      : v.read ? "read" : "not read (see the warnings)";
    const readings = PH.el("td");
    for (const r of v.readings) readings.append(PH.el("span", readingText(r), {class: "reading"}));
    const shows = [];  // [text, class]: what the model could not see greyed
    const hiddenClearance = PH.notObservableText(latest, "clearance");
    const hiddenClasses = PH.notObservableText(latest, "fault");
    if (v.role === "reversal" && hiddenClearance) shows.push([`clearance ${hiddenClearance}`, "not-observable"]);
    else if (v.clearance && PH.finite(v.clearance.estimate)) shows.push([`clearance ${PH.clearanceText(v)} µm`, ""]);
    const classes = Object.entries(v.classes);
    if (hiddenClasses && classes.length) {
      shows.push([`${classes.map(([name]) => name).join(", ")}: ${hiddenClasses}`, "not-observable"]);
    } else {
      for (const [name, p] of classes) shows.push([`P(${name}) ${p.toFixed(2)}`, ""]);
    }
    const cell = PH.el("td", shows.length ? null : "–");
    shows.forEach(([text, cls], i) => cell.append(PH.el("span", (i ? ", " : "") + text, {class: cls})));
    row.append(PH.el("th", v.role.replace("_", " "), {scope: "row"}), PH.el("td", v.phase ?? "–"),
      PH.el("td", verdict, {class: v.read ? "" : "not-read"}), readings, cell);
    return row;
  });
  document.querySelector("#check-phases tbody").replaceChildren(...rows);
}

// The prognosis' headline, as the library's one rule words it (Prognosis.headline: the median
// RUL with its 90 % interval, the latest clearance and the threshold; never "0 h" while the
// clearance is below the threshold), coloured by its state.
function showPrognosis(prognosis) {
  const rul = document.getElementById("rul");
  const detail = document.getElementById("rul-detail");
  if (prognosis && prognosis.headline) {
    rul.textContent = prognosis.headline.text;
    rul.classList.add(`rul-${prognosis.headline.state}`);
    detail.textContent = `Median and 90 % interval of the remaining useful life, by the ` +
      `${prognosis.method} method.`;
    PH.fill(document.getElementById("rul-warnings"), prognosis.warnings || []);
  } else {
    rul.textContent = "–";
    detail.textContent = prognosis && prognosis.error ? prognosis.error : "No prognosis.";
  }
}

// ---------------------------------------------------------------- baseline and evidence
function percent(p) {
  return PH.finite(p) ? `${(100 * p).toFixed(p >= 0.995 || p < 0.01 ? 1 : 0)} %` : "–";
}

function namedText(evidence) {
  const top = PH.topClass(evidence.posterior);
  if (evidence.fault_class !== "cannot_tell") {
    return `${evidence.fault_class} (posterior ${percent(evidence.posterior[evidence.fault_class])})`;
  }
  return top ? `cannot tell (most probable: ${top[0]}, ${percent(top[1])})` : "cannot tell";
}

function showEvidence(summary, data) {
  const note = document.getElementById("evidence-note");
  const baseline = summary.baseline;
  const evidence = summary.evidence;
  if (!baseline || !evidence || data.recordings.length === 0) {
    note.textContent = "No recording of this asset has been judged against its own baseline " +
      "yet: its diagnoses were stored before the service kept baselines. The next recording " +
      "sent with its asset id starts the baseline.";
    for (const id of ["baseline-members", "evidence-plots"]) document.getElementById(id).hidden = true;
    return;
  }
  note.textContent = "Each recording is judged against the asset's own baseline — its first " +
    "recordings unless a fault is named in them, and any recording sent with healthy=true — " +
    "and the recordings outside the baseline accumulate the class evidence, older recordings " +
    "counting less.";
  const complete = baseline.needed !== null && baseline.recordings >= baseline.needed;
  document.getElementById("baseline-status").textContent =
    `${baseline.recordings} of ${baseline.needed} recordings` + (complete ? ": complete" : ": in the making");
  document.getElementById("baseline-detail").textContent = complete
    ? "Every later recording is scored against it: its distance from the baseline and the change statistic."
    : `${baseline.needed - baseline.recordings} more recording(s) needed before changes are scored.`;
  const yesNo = (v) => (v === true ? "yes" : v === false ? "no" : "–");
  const rows = baseline.members.map((m) => {
    const row = PH.el("tr");
    const name = m.filename ? `${m.recording_id} (${m.filename})` : m.recording_id;
    row.append(PH.el("th", name, {scope: "row"}), PH.el("td", PH.hours(m.operating_hours), {class: "num"}),
      PH.el("td", PH.time(m.received_at)), PH.el("td", yesNo(m.healthy)));
    return row;
  });
  document.querySelector("#baseline-members tbody").replaceChildren(...rows);

  const named = document.getElementById("evidence-class");
  named.textContent = namedText(evidence);
  const statistic = PH.finite(evidence.change_statistic)
    ? `${evidence.change_statistic.toFixed(2)} (alarm above ${PH.finite(evidence.change_threshold) ? evidence.change_threshold : "–"})`
    : "– (baseline incomplete)";
  PH.define(document.getElementById("evidence"), [
    ["Recordings accumulated", String(evidence.recordings)],
    ["Named when the posterior reaches", percent(evidence.name_probability)],
    ["Latest distance from the baseline", PH.finite(evidence.distance) ? evidence.distance.toPrecision(3) : "–"],
    ["Change statistic (CUSUM)", statistic],
    ["Change alarm", evidence.change_alarm ? "ALARM: the asset has changed from its baseline" : "no"],
  ]);
  if (evidence.change_alarm) named.classList.add("error");

  const axis = evidenceAxis(data);
  posteriorPlot(axis, evidence.name_probability);
  distancePlot(axis, evidence);
}

// Over operating hours when every recording has them, in the order recorded; else over the
// recording's number (the evidence accumulates in the order the recordings were recorded).
function evidenceAxis(data) {
  const rows = data.recordings;
  const hours = rows.map((r) => r.operating_hours);
  const ordered = hours.every((h, i) => PH.finite(h) && (i === 0 || h >= hours[i - 1]));
  const first = data.total - rows.length + 1;
  const shown = data.truncated ? `the latest ${rows.length} of ${data.total} recordings` : `${rows.length} recording(s)`;
  const text = ordered && rows.length >= 2
    ? `Over operating hours: ${shown}, in the order recorded.`
    : `Over the recordings in the order recorded (${shown}; not every one has operating hours in increasing order).`;
  document.getElementById("posterior-note").textContent = text +
    " The baseline's recordings add no evidence: the posterior stays where it was.";
  return ordered && rows.length >= 2
    ? {rows, xs: hours, time: false, label: "operating hours [h]"}
    : {rows, xs: rows.map((_, i) => first + i), time: false, label: "recording (in the order recorded)"};
}

const onlyPoints = () => null;

function posteriorPlot(axis, threshold) {
  const names = [...new Set(axis.rows.flatMap((r) => Object.keys(r.asset.evidence.posterior || {})))].sort();
  const data = [axis.xs];
  const series = [{label: axis.label}];
  names.forEach((name, i) => {
    data.push(axis.rows.map((r) => {
      const p = (r.asset.evidence.posterior || {})[name];
      return PH.finite(p) ? p : null;
    }));
    series.push({label: name, stroke: PH.palette[i % PH.palette.length], width: 1.5,
      points: {show: true, size: 5}});
  });
  if (PH.finite(threshold)) {
    data.push(axis.xs.map(() => threshold));
    series.push({label: "named at", stroke: "#555", dash: [6, 4], points: {show: false}});
  }
  const options = Object.assign(axisOptions(axis, "posterior"), {series});
  options.scales.y = {range: [0, 1]};
  PH.plot(document.getElementById("posterior-plot"), options, data);
}

function distancePlot(axis, evidence) {
  const rows = axis.rows;
  const statistic = (r) => r.asset.evidence.change_statistic;
  const value = (v) => (PH.finite(v) ? v : null);
  const data = [
    axis.xs,
    rows.map((r) => value(r.distance)),
    rows.map((r) => value(statistic(r))),
    rows.map((r) => (r.asset.evidence.change_alarm ? value(statistic(r)) : null)),
    rows.map((r) => (r.baseline ? 0 : null)),
  ];
  const series = [
    {label: axis.label},
    {label: "distance from the baseline", stroke: PH.palette[0], width: 2, points: {show: true, size: 6}},
    {label: "change statistic (CUSUM)", stroke: PH.palette[3], width: 1.5, points: {show: true, size: 5}},
    {label: "alarm", stroke: "#d62728", paths: onlyPoints, points: {show: true, size: 10, fill: "#d62728"}},
    {label: "baseline recording", stroke: PH.palette[2], paths: onlyPoints, points: {show: true, size: 8, fill: PH.palette[2]}},
  ];
  if (PH.finite(evidence.change_threshold)) {
    data.push(axis.xs.map(() => evidence.change_threshold));
    series.push({label: "alarm threshold", stroke: "#d62728", dash: [10, 5], points: {show: false}});
  }
  const alarms = rows.filter((r) => r.asset.evidence.change_alarm).length;
  const scored = rows.filter((r) => PH.finite(r.distance)).length;
  document.getElementById("distance-note").textContent = scored
    ? `The distance is the RMS of the recording's robust z-scores against the baseline (about 1 ` +
      `for a recording like the baseline's); the change statistic adds what exceeds ` +
      `${PH.finite(evidence.change_reference) ? evidence.change_reference : "its reference"} and ` +
      `alarms above its threshold. ${alarms} recording(s) in alarm.`
    : "No recording has been scored yet: the baseline is incomplete.";
  const options = Object.assign(axisOptions(axis, "distance / statistic"), {series});
  PH.plot(document.getElementById("distance-plot"), options, data);
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

// The clearance where the model saw it in blue; where not (PH.observable), the estimate a hollow
// grey point in a grey interval: shown for context, never read as the unit's clearance.
function clearancePlot(axis, prognosis) {
  const value = (v) => (PH.finite(v) ? v * 1e6 : null);
  const clearance = (e) => e.diagnosis.clearance || {};
  const seen = axis.rows.map((e) => PH.observable(e.diagnosis, "clearance"));
  const column = (key, shown) => axis.rows.map((e, i) => (seen[i] === shown ? value(clearance(e)[key]) : null));
  const data = [
    axis.xs,
    column("estimate", true), column("lower", true), column("upper", true),
    column("estimate", false), column("lower", false), column("upper", false),
  ];
  const blue = PH.palette[0];
  const grey = "#9aa0a6";
  const series = [
    {label: axis.label},
    {label: "clearance [µm]", stroke: blue, width: 2, points: {show: true, size: 6}},
    {label: "90 % lower", stroke: "rgba(31,119,180,0.6)", dash: [4, 4]},
    {label: "90 % upper", stroke: "rgba(31,119,180,0.6)", dash: [4, 4]},
    {label: `${PH.NOT_OBSERVABLE}: estimate`, stroke: grey, paths: onlyPoints,
      points: {show: true, size: 8, stroke: grey, fill: "#fff"}},
    {label: `${PH.NOT_OBSERVABLE}: interval lower`, stroke: grey, dash: [2, 3],
      points: {show: true, size: 4, stroke: grey, fill: grey}},
    {label: `${PH.NOT_OBSERVABLE}: interval upper`, stroke: grey, dash: [2, 3],
      points: {show: true, size: 4, stroke: grey, fill: grey}},
  ];
  if (prognosis && PH.finite(prognosis.threshold)) {
    data.push(axis.xs.map(() => prognosis.threshold * 1e6));
    series.push({label: "failure threshold [µm]", stroke: PH.palette[1], dash: [10, 5]});
  }
  const options = Object.assign(axisOptions(axis, "clearance [µm]"), {
    series,
    bands: [{series: [3, 2], fill: "rgba(31,119,180,0.15)"}, {series: [6, 5], fill: "rgba(154,160,166,0.15)"}],
  });
  const hidden = seen.filter((s) => !s).length;
  if (hidden) {
    document.getElementById("trend-note").textContent += ` ${hidden} diagnosis(es) could not ` +
      `see the clearance (${PH.NOT_OBSERVABLE}): their estimate is a hollow grey point in a ` +
      "grey interval, not a reading.";
  }
  PH.plot(document.getElementById("clearance-plot"), options, data);
}

// The class probabilities of the diagnoses that could see the fault; the others have none.
function classPlot(axis) {
  const names = [...new Set(axis.rows.flatMap((e) => Object.keys(e.diagnosis.class_probabilities || {})))].sort();
  const seen = axis.rows.map((e) => PH.observable(e.diagnosis, "fault"));
  const data = [axis.xs];
  const series = [{label: axis.label}];
  names.forEach((name, i) => {
    data.push(axis.rows.map((e, k) => {
      const p = (e.diagnosis.class_probabilities || {})[name];
      return seen[k] && PH.finite(p) ? p : null;
    }));
    series.push({label: name, stroke: PH.palette[i % PH.palette.length], width: 1.5,
      points: {show: true, size: 5}});
  });
  const hidden = seen.filter((s) => !s).length;
  document.getElementById("class-note").textContent = hidden
    ? `${hidden} diagnosis(es) could not see the fault class (${PH.NOT_OBSERVABLE}): no ` +
      "probabilities are drawn for them."
    : "";
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
