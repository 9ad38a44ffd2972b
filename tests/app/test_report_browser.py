"""The HTML report opens in a real headless browser and shows its plots.

The browser (Chromium from Debian's packages: ``make browser``) loads a probe page
that frames the report and reads, for every image, whether it loaded and its natural
size as decoded by the browser: a missing or broken PNG has naturalWidth 0.
"""
import re
import shutil
import subprocess

import pytest

pytestmark = pytest.mark.slow
BROWSER = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")

PROBE = """<!DOCTYPE html><html><body><pre id="out">pending</pre>
<iframe id="f" src="report.html" width="1200" height="900"></iframe>
<script>
document.getElementById('f').onload = function () {
  var d = this.contentDocument, imgs = d.images, rows = [];
  for (var i = 0; i < imgs.length; i++)
    rows.push('IMG ' + imgs[i].getAttribute('src') + ' ' + imgs[i].complete + ' '
              + imgs[i].naturalWidth + ' ' + imgs[i].naturalHeight + ' ' + imgs[i].width);
  rows.push('TABLES ' + d.getElementsByTagName('table').length);
  rows.push('TITLE ' + d.title);
  document.getElementById('out').textContent = rows.join('\\n');
};
</script></body></html>
"""


@pytest.mark.skipif(BROWSER is None, reason="no Chromium found (make browser installs it with apt-get as root)")
def test_report_renders_its_plots_in_headless_chromium(small_run):
    _, out, rec = small_run
    probe = out / "_probe.html"
    probe.write_text(PROBE)
    try:
        dom = subprocess.run([BROWSER, "--headless", "--no-sandbox", "--disable-gpu",
                              "--allow-file-access-from-files", "--virtual-time-budget=10000",
                              "--dump-dom", probe.as_uri()], capture_output=True, text=True, timeout=120).stdout
    finally:
        probe.unlink()
    images = re.findall(r"IMG (\S+) (\w+) (\d+) (\d+) (\d+)", dom)
    pngs = sorted(f"{s.kind.folder(s)}/{n}" for s in rec.plan.stages if s.name in rec.results
                  for n in rec.results[s.name].files if n.endswith(".png"))
    assert len(pngs) >= 7                             # curve, stick/slip, traction, loop, 3 FRF plots
    assert sorted(src for src, *_ in images) == pngs
    for src, complete, w, h, shown in images:
        assert complete == "true" and int(w) > 100 and int(h) > 100 and int(shown) > 100, src
    assert int(re.search(r"TABLES (\d+)", dom).group(1)) >= 2   # the plan and the numbers
    assert "small test scene" in re.search(r"TITLE (.*)", dom).group(1)
