// The notebook widget's front end (anywidget): implc/api/widget.py sends viewer.js and then
// this file as one ES module, so `implcMount` below is viewer.js's, the page's own viewer.
// Each view gets a shadow root: the viewer's ids and style stay inside it, so several
// widgets (or one widget shown twice) live in one notebook. The kernel compiled the
// shaders (`_data`); `params` is synchronised both ways.
export default {
  render({ model, el }) {
    const shadow = el.attachShadow({ mode: "open" });
    const style = document.createElement("style");
    style.textContent = model.get("_style");
    const box = document.createElement("div");
    box.className = "implc-widget";
    box.style.height = model.get("size") + "px";
    box.innerHTML = model.get("_markup");
    shadow.append(style, box);
    const viewer = implcMount(shadow, model.get("_data"), {
      size: model.get("size"),
      backend: model.get("backend"),
      onParams(params) {
        model.set("params", params);
        model.save_changes();
      },
      onError(message) {
        model.set("error", message);
        model.save_changes();
      },
    });
    viewer.setParams(model.get("params"));
    el.implcViewer = viewer;  // what the JupyterLab test reads
    const update = () => viewer.setParams(model.get("params"));
    model.on("change:params", update);
    return () => {
      model.off("change:params", update);
      viewer.dispose();
    };
  },
};
