// The mission's keepout and speed zones (Nav2 costmap filters) as a map overlay, drawn
// by the server (GET /api/map/image?layer=zones). Kept apart from studio.js: it only
// reads studio.js's map, S and api, and adds one toggle of its own.
"use strict";
(() => {
  let overlay = null;
  const control = L.control({ position: "topright" });
  control.onAdd = () => {
    const d = L.DomUtil.create("label", "costmap-toggle");
    d.innerHTML = '<input type="checkbox" id="zones-toggle" data-testid="zones-toggle"> keepout / speed zones';
    L.DomEvent.disableClickPropagation(d);
    return d;
  };
  control.addTo(map);
  async function show() {
    if (overlay) { overlay.remove(); overlay = null; }
    const key = (S.doc && S.doc.map) || "";
    const query = key ? `?map=${encodeURIComponent(key)}` : "";
    const info = await api("GET", `/api/map${query}`);
    if (!info.ok) return;
    const b = info.data.bounds_m;
    const bounds = L.latLngBounds(L.latLng(b.ymin, b.xmin), L.latLng(b.ymax, b.xmax));
    const sep = query ? "&" : "?";
    overlay = L.imageOverlay(`/api/map/image${query}${sep}layer=zones`, bounds, { zIndex: 3 });
    overlay.addTo(map);
    overlay.getElement().dataset.testid = "zones-image";
  }
  document.getElementById("zones-toggle").addEventListener("change", (e) => {
    if (e.target.checked) show(); else if (overlay) { overlay.remove(); overlay = null; }
  });
})();
