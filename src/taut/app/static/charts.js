// Charts of the taut app, drawn with the vendored Plotly.js (static/vendor/, MIT; nothing
// is fetched from the internet). Every 2D chart has axis titles with their units and its
// legend above the plotting area, never over the curves; every 3D view is turned with the
// mouse and keeps its camera when its data change (uirevision).
"use strict";

// No mode bar (it would cover the legends): drag zooms a 2D chart (double-click resets)
// and turns a 3D view (scroll zooms it). WebGL drawn at the CSS pixel size.
const CHART_CONFIG = {displayModeBar: false, scrollZoom: false, doubleClick: "reset",
                      plotGlPixelRatio: 1};
const CHART3D_CONFIG = Object.assign({}, CHART_CONFIG, {scrollZoom: true});

function axis2d(title, extra) {
  return Object.assign({title: {text: title}, showline: true, mirror: true, ticks: "outside",
                        linecolor: "#888", gridcolor: "#eee", zeroline: false,
                        automargin: true}, extra || {});
}

// A 2D chart on `div`: Plotly traces, axis titles (with units in brackets). Options:
// equal (1:1 aspect, for maps), shapes, annotations, drag (false: the chart is an editor,
// pointer drags are the page's), x / y (extra axis settings).
function chart2d(div, traces, xTitle, yTitle, opts = {}) {
  const layout = {
    margin: {l: 58, r: 12, t: 8, b: 42}, font: {size: 11},
    xaxis: axis2d(xTitle, opts.x), yaxis: axis2d(yTitle, opts.y),
    showlegend: traces.some(t => t.name && t.showlegend !== false),
    legend: {orientation: "h", x: 0, xanchor: "left", y: 1.02, yanchor: "bottom"},
    shapes: opts.shapes || [], annotations: opts.annotations || [],
    hovermode: "closest", uirevision: opts.revision || div.id,
    dragmode: opts.drag === false ? false : "zoom",
  };
  if (opts.equal) Object.assign(layout.yaxis, {scaleanchor: "x", scaleratio: 1});
  return Plotly.react(div, traces, layout, CHART_CONFIG);
}

function axis3d(title, extra) {
  return Object.assign({title: {text: title}, backgroundcolor: "#fafafa", showbackground: true,
                        gridcolor: "#ddd"}, extra || {});
}

// Aspect ratio of the traces' bounding box, the longest side `zoom` (true proportions;
// with an orthographic camera the aspect ratio, not the eye's distance, sets the size).
function trueAspect(traces, zoom) {
  const span = ["x", "y", "z"].map(k => {
    const v = traces.flatMap(t => t[k] || []).filter(a => a !== null && isFinite(a));
    return v.length ? Math.max(...v) - Math.min(...v) : 0;
  });
  const top = (Math.max(...span) || 1) / zoom;
  return {x: Math.max(span[0] / top, 0.05 * zoom), y: Math.max(span[1] / top, 0.05 * zoom),
          z: Math.max(span[2] / top, 0.05 * zoom)};
}

// A 3D view on `div`: traces and the three axis titles (with units). The legend sits
// right of the scene; the scene keeps true proportions; opts.zoom (default 1) scales it
// (above 1 for long, flat scenes).
function chart3d(div, traces, titles, opts = {}) {
  const layout = {
    margin: {l: 0, r: 0, t: 0, b: 0}, font: {size: 11},
    scene: {xaxis: axis3d(titles[0]), yaxis: axis3d(titles[1]), zaxis: axis3d(titles[2]),
            aspectmode: "manual", aspectratio: trueAspect(traces, opts.zoom || 1), domain: {x: [0, 0.74], y: [0, 1]},
            camera: {eye: {x: 1.0, y: -1.2, z: 0.8}, projection: {type: "orthographic"}}},
    showlegend: true, legend: {x: 0.75, xanchor: "left", y: 1, yanchor: "top"},
    uirevision: opts.revision || div.id, annotations: opts.annotations || [],
  };
  return Plotly.react(div, traces, layout, CHART3D_CONFIG);
}

// Plotly line trace (a polyline; null breaks it).
function line(x, y, name, color, extra) {
  return Object.assign({type: "scatter", mode: "lines", x, y, name,
                        line: {color, width: 1.6}}, extra || {});
}

function line3(pts, name, color, extra) {
  return Object.assign({type: "scatter3d", mode: "lines", name,
                        x: pts.map(p => p === null ? null : p[0]),
                        y: pts.map(p => p === null ? null : p[1]),
                        z: pts.map(p => p === null ? null : p[2]),
                        line: {color, width: 4}, hoverinfo: "skip"}, extra || {});
}

// Segments a[i] -> b[i] as one trace (null between segments).
function segments3(pairs, name, color, extra) {
  const pts = [];
  for (const [a, b] of pairs) pts.push(a, b, null);
  return line3(pts, name, color, extra);
}

// A closed polygon as one filled 2D trace.
function polygon(P, name, fill, stroke, extra) {
  const Q = P.concat([P[0]]);
  return Object.assign({type: "scatter", mode: "lines", x: Q.map(p => p[0]), y: Q.map(p => p[1]),
                        name, fill: "toself", fillcolor: fill, line: {color: stroke, width: 1},
                        hoverinfo: "skip"}, extra || {});
}

// A vertical cursor line at x (a shape over the whole plotting height).
function cursor(x) {
  return {type: "line", xref: "x", yref: "paper", x0: x, x1: x, y0: 0, y1: 1,
          line: {color: "#c00", width: 1}};
}

// Screen pixel (client coordinates) <-> data coordinates of a 2D chart.
function chartData(div, evt) {
  const fl = div._fullLayout, r = div.getBoundingClientRect();
  return [fl.xaxis.p2l(evt.clientX - r.left - fl.xaxis._offset),
          fl.yaxis.p2l(evt.clientY - r.top - fl.yaxis._offset)];
}

function chartScreen(div, x, y) {
  const fl = div._fullLayout, r = div.getBoundingClientRect();
  return [r.left + fl.xaxis._offset + fl.xaxis.l2p(x), r.top + fl.yaxis._offset + fl.yaxis.l2p(y)];
}

// Pointer drags on a chart whose dragmode is off: `start(xy, evt)` decides whether a
// press begins a drag (returns true), then `move(xy)` per move and `end()` on release.
function chartDrag(div, start, move, end) {
  let on = false;
  div.addEventListener("pointerdown", e => {
    if (!div._fullLayout || !start(chartData(div, e), e)) return;
    on = true; e.preventDefault(); e.stopPropagation();
    div.setPointerCapture(e.pointerId);
  }, true);
  div.addEventListener("pointermove", e => { if (on) { e.stopPropagation(); move(chartData(div, e)); } }, true);
  div.addEventListener("pointerup", e => { if (on) { on = false; e.stopPropagation(); end(); } }, true);
}

// Axis titles of every chart on the page (for the tests): [{id, axes: [titles]}].
function chartAxes() {
  return [...document.querySelectorAll(".js-plotly-plot")].filter(d => d.offsetParent !== null).map(d => {
    const L = d.layout || {}, s = L.scene;
    const t = a => (a && a.title && a.title.text) || "";
    return {id: d.id, axes: s ? [t(s.xaxis), t(s.yaxis), t(s.zaxis)] : [t(L.xaxis), t(L.yaxis)]};
  });
}
