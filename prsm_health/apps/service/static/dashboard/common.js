// Shared helpers of the dashboard pages (prsm-health). Every text that comes from data is
// inserted with textContent, never as HTML; links are built from encodeURIComponent.
"use strict";

const PH = (() => {
  const plots = [];
  const palette = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
    "#7f7f7f", "#bcbd22", "#17becf"];

  function el(tag, text, attrs) {
    const node = document.createElement(tag);
    if (text !== undefined && text !== null) node.textContent = String(text);
    for (const [key, value] of Object.entries(attrs || {})) {
      if (key === "class") node.className = value;
      else node.setAttribute(key, value);
    }
    return node;
  }

  function assetHref(id) {
    return "/assets/" + encodeURIComponent(id);
  }

  async function getJSON(url, options) {
    const response = await fetch(url, Object.assign({credentials: "same-origin"}, options));
    let body = null;
    try {
      body = await response.json();
    } catch (err) {
      body = null;
    }
    if (response.status === 401) {  // the session ended: log in again, then come back
      location.assign("/login?next=" + encodeURIComponent(location.pathname));
    }
    if (!response.ok) {
      const error = new Error((body && body.error) || `${response.status} ${response.statusText}`);
      error.status = response.status;
      throw error;
    }
    return body;
  }

  const finite = (v) => typeof v === "number" && Number.isFinite(v);
  const um = (v) => (finite(v) ? (v * 1e6).toFixed(2) : "–");
  const hours = (v) => (finite(v) ? (Math.abs(v) >= 100 ? v.toFixed(0) : v.toPrecision(3)) : "–");

  // A target the model could not see is shown as "not observable", never as a number: the
  // rule of prsm_health/diagnostics/not_observable.py, on the same JSON fields. Observable: seen in
  // the window, or in any window of a recording (a share > 0), or a clearance a health check
  // measured; a diagnosis without observability (stored before it was kept) as it was.
  const NOT_OBSERVABLE = "not observable";

  function observable(diagnosis, target) {
    if (target === "clearance" && diagnosis.measured_clearance) return true;
    const seen = (diagnosis.observability || {})[target];
    return seen === undefined || seen === null || Boolean(seen);
  }

  // The text instead of the target's numbers (the clearance with its interval as context),
  // with why where the diagnosis says (undecided.missing); null where it is observable.
  function notObservableText(diagnosis, target) {
    if (!diagnosis || observable(diagnosis, target)) return null;
    const u = diagnosis.undecided;
    const missing = u && u.kind === "not_observable" ? u.missing || [] : [];
    let text = missing.length ? `${NOT_OBSERVABLE} — needs ${missing.join(", ")}` : NOT_OBSERVABLE;
    const c = diagnosis.clearance || {};
    if (target === "clearance" && finite(c.lower) && finite(c.upper)) {
      text += ` (interval ${(c.lower * 1e6).toFixed(1)}–${(c.upper * 1e6).toFixed(1)} µm)`;
    }
    return text;
  }

  // The class "not-observable" (greyed) for a target the model could not see, else "".
  function observableClass(diagnosis, target) {
    return diagnosis && !observable(diagnosis, target) ? "not-observable" : "";
  }

  function clearanceText(diagnosis) {
    const hidden = notObservableText(diagnosis, "clearance");
    if (hidden) return hidden;
    const c = diagnosis && diagnosis.clearance;
    if (!c || !finite(c.estimate)) return "–";
    return `${um(c.estimate)} (${um(c.lower)} – ${um(c.upper)})`;
  }

  function time(iso) {  // stored as UTC ISO-8601
    return iso ? iso.slice(0, 19).replace("T", " ") : "–";
  }

  function topClass(probabilities) {
    let best = null;
    for (const [name, p] of Object.entries(probabilities || {})) {
      if (best === null || p > best[1]) best = [name, p];
    }
    return best;
  }

  function classText(diagnosis) {
    const probabilities = diagnosis.class_probabilities || {};
    const name = diagnosis.fault_class;
    const hidden = notObservableText(diagnosis, "fault");
    if (name && hidden && Object.keys(probabilities).length) return `${name} (${hidden})`;
    if (name && finite(probabilities[name])) return `${name} (${probabilities[name].toFixed(2)})`;
    const top = topClass(probabilities);
    if (!name) return "–";
    return top ? `${name} (most probable: ${top[0]} ${top[1].toFixed(2)})` : name;
  }

  function fill(list, items) {
    list.replaceChildren(...items.map((text) => el("li", text)));
  }

  // Terms and values; a third item gives the value's class (e.g. "not-observable").
  function define(dl, pairs) {
    dl.replaceChildren();
    for (const [term, value, cls] of pairs) dl.append(el("dt", term), el("dd", value, cls ? {class: cls} : {}));
  }

  function plot(container, options, data) {
    const width = Math.max(320, container.clientWidth || 800);
    const u = new uPlot(Object.assign({width, height: 280}, options), data, container);
    plots.push([u, container]);
    return u;
  }

  window.addEventListener("resize", () => {
    for (const [u, container] of plots) u.setSize({width: Math.max(320, container.clientWidth), height: 280});
  });

  // Vertical lines with labels at given x values (defect frequencies): a uPlot plugin that
  // draws on the plot's canvas after the series.
  function markers(lines) {
    return {
      hooks: {
        draw: [(u) => {
          const ctx = u.ctx;
          const {left, top, width, height} = u.bbox;
          const dpr = window.devicePixelRatio || 1;
          ctx.save();
          ctx.beginPath();
          ctx.rect(left, top, width, height);
          ctx.clip();
          ctx.font = `${Math.round(11 * dpr)}px sans-serif`;
          ctx.textAlign = "left";  // uPlot leaves its axes' alignment set
          ctx.textBaseline = "alphabetic";
          ctx.lineWidth = dpr;
          lines.forEach((line) => {
            const x = Math.round(u.valToPos(line.x, "x", true));
            if (!(x >= left && x <= left + width)) return;
            ctx.strokeStyle = line.color;
            ctx.fillStyle = line.color;
            ctx.setLineDash([5 * dpr, 4 * dpr]);
            ctx.beginPath();
            ctx.moveTo(x, top);
            ctx.lineTo(x, top + height);
            ctx.stroke();
            ctx.setLineDash([]);
            // the label along the line, reading downwards, on its right
            ctx.save();
            ctx.translate(x + 3 * dpr, top + 4 * dpr);
            ctx.rotate(Math.PI / 2);
            ctx.fillText(line.label, 0, 0);
            ctx.restore();
          });
          ctx.restore();
        }],
      },
    };
  }

  function ready(fn) {
    if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", fn);
    else fn();
  }

  return {el, assetHref, getJSON, finite, um, hours, NOT_OBSERVABLE, observable, notObservableText,
    observableClass, clearanceText, time, topClass, classText, fill, define, plot, markers, palette,
    ready};
})();
