// Page start-up: tabs, the shared "copy link" and "download YAML" buttons, and restoring
// a view from the URL (or the scenario given to `taut app SCENARIO`).
"use strict";

const VIEWS = {sheet: SheetView, plan: PlanView, cdpr: CdprView};

function showView(name) {
  taut.current = name;
  for (const v of Object.keys(VIEWS)) {
    document.getElementById("view-" + v).classList.toggle("active", v === name);
    document.getElementById("tab-" + v).classList.toggle("active", v === name);
  }
  const view = VIEWS[name];
  if (view.saveUrl) view.saveUrl();
}

async function downloadCurrent() {
  const name = taut.current, v = VIEWS[name];
  let r;
  if (name === "sheet" && v.sc) r = await api("/api/sheet/yaml", {scenario: v.scenario()});
  else if (name === "plan" && v.sc) r = await api("/api/plan/yaml", {scenario: v.sc});
  else if (name === "cdpr" && v.model) r = await api("/api/cdpr/yaml", v.body({pose: v.pose}));
  else { showMessage("nothing loaded to download", "error"); return; }
  if (r.ok) { taut.lastYaml = r.data.yaml; download(r.data.yaml, r.data.filename); }
}

async function restore() {
  const hash = location.hash.slice(1);
  if (hash) {
    let st = null;
    try { st = decodeState(hash); } catch (e) { showMessage("link: cannot read the view in this URL", "error"); }
    if (st && st.v === "sheet") { showView("sheet"); return SheetView.load({scenario: st.s}); }
    if (st && st.v === "plan") { showView("plan"); return PlanView.load({scenario: st.s}, {run: st.k !== null, k: st.k, options: st.o}); }
    if (st && st.v === "cdpr") {
      showView("cdpr");
      return CdprView.load(st.src, {pose: st.pose, stabilisers: st.stab, method: st.method});
    }
  }
  const init = (await api("/api/initial")).data.initial;
  if (init) {
    showView(init.kind);
    if (init.kind === "sheet") return SheetView.load({scenario: init.mapping});
    if (init.kind === "plan") return PlanView.load({scenario: init.mapping});
    return CdprView.load({model: init.mapping});
  }
  showView("sheet");
  const names = taut.catalog.sheet;
  if (names.includes("example2_r2_r4_353mm.yaml")) return SheetView.load({example: "example2_r2_r4_353mm.yaml"});
  return SheetView.load({regular: 8});
}

window.addEventListener("DOMContentLoaded", async () => {
  const cat = await api("/api/catalog");
  taut.catalog = cat.ok ? cat.data : {sheet: [], plan: [], cdpr: []};
  SheetView.init(taut.catalog.sheet);
  PlanView.init(taut.catalog.plan);
  CdprView.init(taut.catalog.cdpr);
  for (const b of document.querySelectorAll(".tab")) b.addEventListener("click", () => showView(b.dataset.view));
  document.getElementById("download").addEventListener("click", downloadCurrent);
  document.getElementById("share").addEventListener("click", async () => {
    try { await navigator.clipboard.writeText(location.href); showMessage("link copied: it reopens this view", "info"); }
    catch (e) { showMessage("copy this page's address to share the view", "info"); }
  });
  await restore();
  taut.ready = true;
  document.body.dataset.ready = "1";
});
