// Typeset the math that pymdownx.arithmatex marks (generic mode: \( \) inline, \[ \] display)
// with the KaTeX served from this site (docs/assets/katex), on every page load and on
// mkdocs-material's instant navigation.
function dceeTypeset(root) {
  root.querySelectorAll(".arithmatex").forEach(function (el) {
    renderMathInElement(el, {
      delimiters: [
        { left: "\\(", right: "\\)", display: false },
        { left: "\\[", right: "\\]", display: true },
      ],
      throwOnError: false,
    });
  });
}
if (typeof document$ !== "undefined") {
  document$.subscribe(function () { dceeTypeset(document.body); });
} else {
  document.addEventListener("DOMContentLoaded", function () { dceeTypeset(document.body); });
}
