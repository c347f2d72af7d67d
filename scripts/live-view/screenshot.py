# The screenshots of docs/guide/live-view.md: opens Lichtblick's web build (served by
# serve.py) in headless Chromium at URL (a data source in its `ds` parameters), imports LAYOUT
# through the Layouts tab's "Import from file" (the browser's file picker answered with the
# layout's file), closes the sidebar, waits WAIT_S, takes PREFIX-1.png, then for each
# SEEK_FRACTION clicks the timeline there and takes PREFIX-seekN.png.
# Usage: screenshot.py URL LAYOUT PREFIX WAIT_S [SEEK_FRACTION ...]
# Needs: pip install playwright (its Python package; the browser is /usr/bin/chromium).
import sys, time, json
from playwright.sync_api import sync_playwright
url, layout, prefix, wait_s = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
seeks = [float(a) for a in sys.argv[5:]]
text = open(layout).read()
init = """
window.showOpenFilePicker = async () => [{kind: "file", name: "plant-study.json",
  getFile: async () => new File([%s], "plant-study.json", {type: "application/json"})}];
""" % json.dumps(text)
with sync_playwright() as p:
    b = p.chromium.launch(executable_path="/usr/bin/chromium",
                          args=["--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"])
    pg = b.new_page(viewport={"width": 1600, "height": 1000})
    logs = []
    pg.on("console", lambda m: logs.append(f"{m.type}: {m.text}"))
    pg.on("pageerror", lambda e: logs.append(f"PAGEERROR: {e}"))
    pg.add_init_script(init)
    pg.goto(url)
    pg.wait_for_selector("[data-testid=AppMenuButton]", timeout=120000)
    time.sleep(3)
    # Lichtblick 1.x's View > "Import layout from file" does nothing in the web app (its
    # setCurrentLayout is a no-op there); the Layouts tab's "Import from file…" imports.
    pg.click("text=Layouts")
    time.sleep(1)
    pg.on("dialog", lambda d: d.accept())
    pg.click("text=Import from file")
    time.sleep(3)
    # Close the left sidebar: more room for the panels.
    pg.mouse.click(304, 58)
    time.sleep(wait_s)
    pg.screenshot(path=prefix + "-1.png")
    for i, f in enumerate(seeks):
        # The playback bar's timeline, across the window's width near its bottom.
        pg.mouse.click(8 + f * (1590 - 8), 945)
        time.sleep(6)
        pg.screenshot(path=f"{prefix}-seek{i}.png")
    open(prefix + ".log", "w").write("\n".join(l for l in logs if "OTS" not in l and "font" not in l))
    b.close()
