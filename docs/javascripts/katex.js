// Typesets the pages' math with the vendored KaTeX (javascripts/katex/), so it renders offline.
// pymdownx.arithmatex (generic mode) leaves inline math as <span class="arithmatex">\(...\)</span>
// and display math as <div class="arithmatex">\[...\]</div>; each is replaced by KaTeX's output.
// A formula KaTeX cannot parse shows as a red .katex-error (tests/test_site_browser.py looks).
(function () {
  function typeset(root) {
    root.querySelectorAll(".arithmatex").forEach(function (el) {
      if (el.querySelector(".katex")) return; // typeset already
      var tex = el.textContent.trim();
      var display = tex.startsWith("\\[");
      tex = tex.replace(/^\\[([]/, "").replace(/\\[)\]]$/, "");
      katex.render(tex, el, { displayMode: display, throwOnError: false });
    });
  }
  if (typeof document$ !== "undefined") {
    // Material's observable: fires on load and after each instant-navigation page switch
    document$.subscribe(function () { typeset(document.body); });
  } else {
    document.addEventListener("DOMContentLoaded", function () { typeset(document.body); });
  }
})();
