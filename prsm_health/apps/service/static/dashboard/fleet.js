// The fleet overview (/): one row per asset from GET /v1/assets?prognosis=true.
"use strict";

PH.ready(async () => {
  const status = document.getElementById("status");
  const tbody = document.querySelector("#fleet tbody");
  try {
    const page = await PH.getJSON("/v1/assets?prognosis=true&limit=200");
    for (const asset of page.assets) {
      const name = PH.el("th", null, {scope: "row"});
      name.append(PH.el("a", asset.asset_id, {href: PH.assetHref(asset.asset_id)}));
      const row = PH.el("tr");
      row.append(
        name,
        statusCell(asset.status),
        PH.el("td", PH.classText(asset.latest)),
        PH.el("td", PH.clearanceText(asset.latest.clearance), {class: "num"}),
        rulCell(asset.prognosis),
        PH.el("td", asset.diagnoses, {class: "num"}),
        PH.el("td", PH.time(asset.last_received_at)),
        evidenceCell(asset.baseline, asset.evidence),
      );
      tbody.append(row);
    }
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

function rulCell(prognosis) {
  const cell = PH.el("td", null, {class: "num"});
  if (prognosis && prognosis.rul_hours) {
    cell.textContent = PH.rulText(prognosis.rul_hours);
  } else {
    cell.textContent = "–";
    if (prognosis && prognosis.error) cell.append(PH.el("span", prognosis.error, {class: "why"}));
  }
  return cell;
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
