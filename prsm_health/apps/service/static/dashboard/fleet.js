// The fleet overview (/): one row per asset from GET /v1/assets?prognosis=true, most recently
// seen first; the RUL column's header button sorts the rows by RUL (which unit to overhaul
// first), again for the reverse.
"use strict";

PH.ready(async () => {
  const status = document.getElementById("status");
  const tbody = document.querySelector("#fleet tbody");
  try {
    const page = await PH.getJSON("/v1/assets?prognosis=true&limit=200");
    const rows = [];
    for (const asset of page.assets) {
      const name = PH.el("th", null, {scope: "row"});
      name.append(PH.el("a", asset.asset_id, {href: PH.assetHref(asset.asset_id)}));
      const row = PH.el("tr");
      row.append(
        name,
        statusCell(asset.status),
        PH.el("td", PH.classText(asset.latest), {class: PH.observableClass(asset.latest, "fault")}),
        PH.el("td", PH.clearanceText(asset.latest),
          {class: `num ${PH.observableClass(asset.latest, "clearance")}`.trim()}),
        rulCell(asset.prognosis),
        PH.el("td", asset.diagnoses, {class: "num"}),
        PH.el("td", PH.time(asset.last_received_at)),
        evidenceCell(asset.baseline, asset.evidence),
      );
      rows.push({row, urgency: urgency(asset.prognosis)});
      tbody.append(row);
    }
    sortable(tbody, rows);
    if (page.total === 0) {
      status.textContent = "No diagnosis is stored yet: send recordings with an asset id " +
        "(Diagnose a recording, or POST /v1/diagnose).";
    } else {
      status.textContent = page.truncated
        ? `${page.count} most recently seen of ${page.total} assets.`
        : `${page.count} asset(s).`;
    }
  } catch (error) {
    status.textContent = "Could not load the assets: " + error.message;
    status.classList.add("error");
  }
});

// healthy / unknown / watch / alarm, as the service's rule gives it (GET /v1/assets: status), in word
// and colour, with its reasons below
function statusCell(status) {
  const cell = PH.el("td");
  if (!status) {
    cell.textContent = "–";
    return cell;
  }
  cell.append(PH.el("span", status.level, {class: `status-word status-${status.level}`}));
  for (const reason of status.reasons) cell.append(PH.el("span", reason, {class: "why"}));
  return cell;
}

// The RUL in brief as the library's one rule words it (the prognosis' headline: median and
// 90 % interval, never "0 h" while the clearance is below the threshold); the whole headline
// (with the latest clearance and the threshold) below it when the limit is near or reached.
function rulCell(prognosis) {
  const cell = PH.el("td", null, {class: "num"});
  const headline = prognosis && prognosis.headline;
  if (headline) {
    cell.append(PH.el("span", headline.short, {class: `rul-${headline.state}`, title: headline.text}));
    if (headline.state === "at_limit" || headline.state === "threshold_reached") {
      cell.append(PH.el("span", headline.text, {class: "why"}));
    }
  } else {
    cell.textContent = "–";
    if (prognosis && prognosis.error) cell.append(PH.el("span", prognosis.error, {class: "why"}));
  }
  return cell;
}

// Where an asset sorts by RUL: [group, median RUL]. Group 0: the threshold is reached (the
// headline's state); 1: a median RUL; 2: no prognosis, or none with a finite median.
function urgency(prognosis) {
  const headline = prognosis && prognosis.headline;
  if (!headline || headline.state === "unknown") return [2, 0];
  if (headline.state === "threshold_reached") return [0, 0];
  return [1, prognosis.rul_hours.estimate];
}

// The RUL column's header button: ascending (most urgent first: the threshold reached, then
// the smallest median RUL), again descending; assets without a prognosis last either way, ties
// in the order the service listed them (most recently seen first).
function sortable(tbody, rows) {
  const button = document.getElementById("sort-rul");
  const column = document.getElementById("rul-column");
  const mark = button.querySelector(".sort-mark");
  rows.forEach((r, i) => { r.seen = i; });
  button.addEventListener("click", () => {
    const ascending = column.getAttribute("aria-sort") !== "ascending";
    const sign = ascending ? 1 : -1;
    rows.sort((a, b) => {
      const [ga, ra] = a.urgency;
      const [gb, rb] = b.urgency;
      if ((ga === 2) !== (gb === 2)) return ga === 2 ? 1 : -1;
      return sign * (ga - gb || ra - rb) || a.seen - b.seen;
    });
    tbody.append(...rows.map((r) => r.row));
    column.setAttribute("aria-sort", ascending ? "ascending" : "descending");
    mark.textContent = ascending ? "▲" : "▼";
  });
}

// The asset against its own baseline: the class its accumulated evidence names (or the most
// probable), after how many recordings; the baseline while it is in the making; the alarm.
function evidenceCell(baseline, evidence) {
  const cell = PH.el("td");
  if (!baseline || !evidence) {
    cell.textContent = "–";
    return cell;
  }
  if (baseline.needed !== null && baseline.recordings < baseline.needed) {
    cell.textContent = `baseline ${baseline.recordings} of ${baseline.needed}`;
  } else if (evidence.recordings === 0) {
    cell.textContent = "baseline complete; no evidence yet";
  } else {
    const top = PH.topClass(evidence.posterior);
    const name = evidence.fault_class !== "cannot_tell" ? evidence.fault_class : `cannot tell (${top[0]}`;
    const p = evidence.posterior[top[0]].toFixed(2);
    cell.textContent = evidence.fault_class !== "cannot_tell"
      ? `${name} ${p} after ${evidence.recordings}`
      : `${name} ${p}) after ${evidence.recordings}`;
  }
  if (evidence.change_alarm) {
    cell.append(PH.el("span", "changed from its baseline (alarm)", {class: "why error"}));
  }
  return cell;
}
