// Headless Chromium for the browser checks (tests/report/render_check.js,
// tests/web/station_page_check.js): Debian's /usr/bin/chromium (or $PIEZOBENCH_CHROMIUM) driven by
// npm's puppeteer-core, pinned in tests/js/package-lock.json (tests/js/install.sh: `npm ci` when
// missing or stale; the ctest fixture browser.npm_ci runs it). puppeteer-core never downloads a
// browser.
'use strict';
const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');

// puppeteer-core at the version package-lock.json pins (a stale node_modules after a bump fails).
function loadPuppeteer() {
  const install = `run\n    bash ${path.join(__dirname, 'install.sh')}\n(the ctest fixture browser.npm_ci does)`;
  const lock = JSON.parse(fs.readFileSync(path.join(__dirname, 'package-lock.json'), 'utf8'));
  const pinned = lock.packages['node_modules/puppeteer-core'].version;
  let installed = null;
  try {
    installed = JSON.parse(fs.readFileSync(path.join(__dirname, 'node_modules/puppeteer-core/package.json'), 'utf8')).version;
  } catch (e) {
    throw new Error(`puppeteer-core is not installed in ${path.join(__dirname, 'node_modules')}; ${install}`);
  }
  if (installed !== pinned) throw new Error(`node_modules holds puppeteer-core ${installed}, package-lock.json pins ${pinned}; ${install}`);
  return require('puppeteer-core');
}

// Starts headless Chromium with a throw-away profile, no network of its own, a width x height
// viewport. Returns { browser, close }: close() ends the browser (killed after 3 s) and removes the
// profile; call it in a finally.
async function launchChromium(width, height) {
  const executablePath = process.env.PIEZOBENCH_CHROMIUM || '/usr/bin/chromium';
  if (!fs.existsSync(executablePath)) {
    throw new Error(`${executablePath} not found: install Debian's chromium package (scripts/setup.sh does)`);
  }
  const puppeteer = loadPuppeteer();
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'piezobench-chromium-'));
  let browser;
  try {
    browser = await puppeteer.launch({
      executablePath,
      headless: true,
      pipe: true,
      userDataDir: profile,
      defaultViewport: { width, height, deviceScaleFactor: 1 },
      protocolTimeout: 60000,
      // The machine is shared: Chromium may take a while to start under load.
      timeout: 60000,
      args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--disable-quic',
        '--disable-background-networking', '--disable-component-update', '--disable-sync',
        '--disable-extensions', '--mute-audio', '--hide-scrollbars', `--window-size=${width},${height}`],
    });
  } catch (e) {
    fs.rmSync(profile, { recursive: true, force: true });
    throw e;
  }
  const close = async () => {
    const proc = browser.process();
    const closed = await Promise.race([browser.close().then(() => true, () => false),
      new Promise((resolve) => setTimeout(() => resolve(false), 3000))]);
    if (!closed && proc && proc.exitCode === null) proc.kill('SIGKILL');
    fs.rmSync(profile, { recursive: true, force: true });
  };
  return { browser, close };
}

// Collects into `errors` every console error or assert (the console's and the browser's log, as
// puppeteer reports both), uncaught exception, dialog (a sign of injected script, dismissed) and
// request to a URL that allowUrl refuses, of `page`.
function watchPage(page, errors, allowUrl, networkLabel) {
  page.on('console', (m) => {
    if (m.type() === 'error' || m.type() === 'assert') {
      const where = m.location() && m.location().url ? ` (${m.location().url})` : '';
      errors.push(`console.${m.type()}: ${m.text()}${where}`);
    }
  });
  page.on('pageerror', (e) => errors.push('uncaught exception: ' + (e && e.message ? e.message : String(e))));
  page.on('dialog', (d) => {
    errors.push(`a ${d.type()} dialog opened ("${d.message()}"): injected script ran`);
    d.dismiss().catch(() => {});
  });
  page.on('request', (r) => { if (!allowUrl(r.url())) errors.push(networkLabel + r.url()); });
}

module.exports = { launchChromium, watchPage };
