// Drives a page written by label_resources in headless Chromium (Debian's /usr/bin/chromium) the
// way a person would: picks a class in the row of each resource named in CHOICES.json
// ({"mesh:8f8a896cf626910d": 3, ...}; the class ids), optionally presses "Take the proposals",
// presses "Save label table", and writes the file the browser downloaded to OUT.yaml.
//   node label_page.js PAGE_DIR CHOICES.json OUT.yaml [--take-proposals] [--screenshot PNG]
// Exit code 0 = saved, 1 = a row or the download was missing, 2 = usage.
"use strict";
const fs = require("fs");
const path = require("path");
const { chromium } = require("playwright-core");

async function main() {
  const args = process.argv.slice(2);
  const takeProposals = args.includes("--take-proposals");
  const shotAt = args.indexOf("--screenshot");
  const screenshot = shotAt >= 0 ? args[shotAt + 1] : null;
  const positional = args.filter((a, i) => !a.startsWith("--") && (shotAt < 0 || i !== shotAt + 1));
  if (positional.length !== 3) {
    console.error("usage: node label_page.js PAGE_DIR CHOICES.json OUT.yaml [--take-proposals] [--screenshot PNG]");
    process.exit(2);
  }
  const [pageDir, choicesFile, outFile] = positional;
  const choices = JSON.parse(fs.readFileSync(choicesFile, "utf8"));
  const browser = await chromium.launch({
    executablePath: "/usr/bin/chromium",
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
           "--disable-component-update", "--disable-sync"],
  });
  try {
    const page = await browser.newPage({ acceptDownloads: true, viewport: { width: 1400, height: 1000 } });
    await page.goto("file://" + path.resolve(pageDir, "index.html"));
    for (const [id, classId] of Object.entries(choices)) {
      const [kind, key] = id.split(":");
      const select = page.locator('select[name="class-' + kind + "-" + key + '"]');
      if ((await select.count()) !== 1) {
        console.error("label_page: no row for " + id);
        process.exit(1);
      }
      await select.selectOption(String(classId));
    }
    if (takeProposals) await page.click("#accept-proposals");
    if (screenshot) await page.screenshot({ path: screenshot });
    const [download] = await Promise.all([page.waitForEvent("download"), page.click("#save")]);
    await download.saveAs(outFile);
    console.log("label_page: saved " + outFile + " (" + (await page.textContent("#progress")) + ")");
  } finally {
    await browser.close();
  }
}

main().catch((e) => {
  console.error("label_page: " + e.message);
  process.exit(1);
});
