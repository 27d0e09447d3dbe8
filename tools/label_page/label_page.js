// The labelling page (written by label_resources): one row per resource of a capture, most pixels
// first; pick a VIPER class per row, then "Save label table" downloads the YAML that viper's
// instances node reads. Plain JavaScript, no server, no library.
(function () {
  "use strict";
  const data = window.VIPER_LABELS;
  const chosen = new Map();  // "kind:key" -> class id (0 = unlabelled)
  const classById = new Map(data.classes.map((c) => [c.id, c]));

  function rowId(r) { return r.kind + ":" + r.key; }
  function rgbCss(rgb) { return "rgb(" + rgb.join(",") + ")"; }

  function updateProgress() {
    let labelled = 0, pixels = 0;
    for (const r of data.resources) {
      if ((chosen.get(rowId(r)) || 0) !== 0) { labelled += 1; pixels += r.pixels; }
    }
    const share = data.total_pixels ? (100 * pixels / data.total_pixels).toFixed(1) : "0";
    document.getElementById("progress").textContent =
      labelled + " of " + data.resources.length + " resources labelled, " + share + " % of the pixels";
  }

  function applyFilter() {
    const only = document.getElementById("unlabelled-only").checked;
    for (const tr of document.querySelectorAll("#resources tr")) {
      tr.style.display = only && (chosen.get(tr.dataset.id) || 0) !== 0 ? "none" : "";
    }
  }

  function setClass(tr, r, id) {
    chosen.set(rowId(r), id);
    tr.classList.toggle("labelled", id !== 0);
    tr.querySelector(".pick .swatch").style.background = rgbCss(classById.get(id).rgb);
    updateProgress();
  }

  function buildRow(r) {
    const tr = document.createElement("tr");
    tr.dataset.id = rowId(r);
    const crops = r.crops.map((c) => '<img loading="lazy" alt="" src="' + c + '">').join("");
    const share = data.total_pixels ? (100 * r.pixels / data.total_pixels).toFixed(2) : "0";
    const proposal = r.proposal ? classById.get(r.proposal).name + ' <span class="reason">(' + r.reason + ")</span>" : "";
    tr.innerHTML =
      '<td class="crops">' + crops + "</td>" +
      '<td><div class="key">' + r.kind + " " + r.key + "</div>" + r.pixels + " px (" + share + " %), " + r.frames +
      ' frames<br><span class="swatch" style="background:' + rgbCss(r.rgb) + '"></span> mean colour, size ' +
      r.size.map((v) => v.toFixed(1)).join(" × ") + "</td>" +
      "<td>proposed: " + (proposal || "—") + "</td>" +
      '<td class="pick"><span class="swatch"></span> <select></select></td>';
    const select = tr.querySelector("select");
    select.name = "class-" + r.kind + "-" + r.key;
    for (const c of data.classes) {
      const o = document.createElement("option");
      o.value = String(c.id);
      o.textContent = c.id + " " + c.name;
      select.appendChild(o);
    }
    select.value = "0";
    select.addEventListener("change", () => { setClass(tr, r, Number(select.value)); });
    return tr;
  }

  function yaml() {
    const sections = { mesh: [], texture: [], program: [] };
    for (const r of data.resources) {
      const id = chosen.get(rowId(r)) || 0;
      if (id !== 0) sections[r.kind].push('  "' + r.key + '": ' + id);
    }
    let out = "# viper resource label table: resource content key -> VIPER class id\n" +
              "# labelled on the label_resources page of " + data.capture + "\n";
    for (const [kind, name] of [["mesh", "meshes"], ["texture", "textures"], ["program", "programs"]]) {
      const rows = sections[kind].sort();
      out += rows.length ? name + ":\n" + rows.join("\n") + "\n" : name + ": {}\n";
    }
    return out;
  }

  function save() {
    const blob = new Blob([yaml()], { type: "text/yaml" });
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob);
    a.download = "labels.yaml";
    document.body.appendChild(a);
    a.click();
    a.remove();
  }

  document.getElementById("capture").textContent = data.capture + " (" + data.frames + " frames)";
  const body = document.querySelector("#resources tbody");
  for (const r of data.resources) {
    const tr = buildRow(r);
    body.appendChild(tr);
    setClass(tr, r, 0);
  }
  document.getElementById("unlabelled-only").addEventListener("change", applyFilter);
  document.getElementById("save").addEventListener("click", save);
  document.getElementById("accept-proposals").addEventListener("click", () => {
    for (const tr of body.querySelectorAll("tr")) {
      const r = data.resources.find((x) => rowId(x) === tr.dataset.id);
      if ((chosen.get(rowId(r)) || 0) === 0 && r.proposal) {
        tr.querySelector("select").value = String(r.proposal);
        setClass(tr, r, r.proposal);
      }
    }
    applyFilter();
  });
  window.viperLabelYaml = yaml;  // for tests and the console
  updateProgress();
})();
