// Diagnose a recording (/upload): with operating hours the file goes as a binary body to
// POST /v1/diagnose (the diagnosis then counts in the prognosis), without them as a
// multipart upload to POST /v1/diagnose/file.
"use strict";

const BODY_TYPES = {".mcap": "application/vnd.mcap", ".parquet": "application/vnd.apache.parquet"};

PH.ready(() => {
  const form = document.getElementById("upload-form");
  const status = document.getElementById("status");
  form.addEventListener("submit", async (event) => {
    event.preventDefault();
    status.classList.remove("error");
    document.getElementById("result").hidden = true;
    const file = form.elements.file.files[0];
    const assetId = form.elements.asset_id.value.trim();
    const hours = form.elements.operating_hours.value.trim();
    const healthy = form.elements.healthy.checked;
    const name = file ? file.name.toLowerCase() : "";
    const suffix = Object.keys(BODY_TYPES).find((s) => name.endsWith(s));
    if (!suffix) {
      status.textContent = name.endsWith(".csv")
        ? "CSV recordings are not accepted by the service: convert the file to Parquet."
        : "Choose a .mcap or .parquet recording.";
      status.classList.add("error");
      return;
    }
    status.textContent = `Diagnosing ${file.name}…`;
    try {
      let answer;
      if (hours !== "") {
        const query = new URLSearchParams({asset_id: assetId, operating_hours: hours});
        if (healthy) query.set("healthy", "true");
        answer = await PH.getJSON("/v1/diagnose?" + query, {
          method: "POST", body: file, headers: {"content-type": BODY_TYPES[suffix]},
        });
      } else {
        const body = new FormData();
        body.append("asset_id", assetId);
        if (healthy) body.append("healthy", "true");
        body.append("file", file, file.name);
        answer = await PH.getJSON("/v1/diagnose/file", {method: "POST", body});
      }
      show(answer, assetId);
      status.textContent = `Diagnosed ${file.name}; stored for asset ${assetId}.`;
    } catch (error) {
      status.textContent = "Not diagnosed: " + error.message;
      status.classList.add("error");
    }
  });
});

// The asset's state after this recording: its baseline and accumulated evidence.
function assetRows(asset) {
  if (!asset) return [];
  const rows = [];
  if (asset.baseline) {
    const b = asset.baseline;
    const distance = PH.finite(b.distance) ? `; distance from it ${b.distance.toPrecision(3)}` : "";
    rows.push(["Asset's baseline", `${b.recordings} of ${b.needed} recordings${distance}`]);
  }
  if (asset.evidence) {
    const e = asset.evidence;
    const alarm = e.change_alarm ? "; change alarm" : "";
    rows.push(["Asset's evidence", `${e.fault_class} after ${e.recordings} recording(s)${alarm}`]);
  }
  return rows;
}

function show(answer, assetId) {
  const diagnosis = answer.diagnosis || answer;  // an upload wraps it with its windows
  const windows = answer.recording ? answer.windows.length : (diagnosis.windows || []).length || 1;
  PH.define(document.getElementById("diagnosis"), [
    ["Fault class (probability)", PH.classText(diagnosis), PH.observableClass(diagnosis, "fault")],
    ["Classes not ruled out", (diagnosis.class_set || []).join(", ") || "–"],
    ["Clearance [µm] (90 % interval)", PH.clearanceText(diagnosis), PH.observableClass(diagnosis, "clearance")],
    ["Windows", String(windows)],
    ...assetRows(diagnosis.asset),
    ["Model", `${diagnosis.model.name} ${diagnosis.model.version} (${diagnosis.model.design})`],
  ]);
  PH.fill(document.getElementById("result-warnings"),
    [...(answer.warnings && answer.recording ? answer.warnings : []), ...(diagnosis.warnings || [])]);
  const link = document.getElementById("asset-link");
  link.href = PH.assetHref(assetId);
  link.textContent = `Open asset ${assetId}`;
  document.getElementById("result").hidden = false;
}
