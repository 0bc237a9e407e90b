// The DevTools protocol over a pipe, shared by the browser checks (tests/report/render_check.js,
// tests/web/station_page_check.js): Debian's Chromium started headless with
// --remote-debugging-pipe (file descriptors 3 and 4), no npm package.
'use strict';

// ---- DevTools protocol over a pipe -------------------------------------------------------------
class Cdp {
  constructor(writable, readable) {
    this.writable = writable;
    this.nextId = 1;
    this.pending = new Map();
    this.listeners = [];
    let buffered = '';
    readable.on('data', (chunk) => {
      buffered += chunk.toString('utf8');
      let end;
      while ((end = buffered.indexOf('\0')) >= 0) {
        const message = JSON.parse(buffered.slice(0, end));
        buffered = buffered.slice(end + 1);
        if (message.id !== undefined && this.pending.has(message.id)) {
          const { resolve, reject, method } = this.pending.get(message.id);
          this.pending.delete(message.id);
          if (message.error) reject(new Error(`${method}: ${message.error.message}`));
          else resolve(message.result);
        } else if (message.method) {
          for (const listener of this.listeners) listener(message);
        }
      }
    });
  }
  send(method, params = {}, sessionId = undefined) {
    const id = this.nextId++;
    const message = { id, method, params };
    if (sessionId) message.sessionId = sessionId;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, method });
      this.writable.write(JSON.stringify(message) + '\0');
    });
  }
  on(listener) { this.listeners.push(listener); }
}


// Chromium's command line: headless, no network of its own, a throw-away profile.
function chromiumArgs(profile, width, height) {
  return [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--disable-quic',
    '--no-first-run', '--no-default-browser-check', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--disable-extensions', '--mute-audio',
    '--hide-scrollbars', '--remote-debugging-pipe', `--user-data-dir=${profile}`,
    `--window-size=${width},${height}`, 'about:blank',
  ];
}

// Collects into `errors` every console error or assert, uncaught exception, error log entry, dialog
// (a sign of injected script) and request to a URL that allowUrl refuses, of the page `sessionId`.
function watchConsole(cdp, sessionId, page, errors, allowUrl, networkLabel) {
  cdp.on((m) => {
    if (m.sessionId !== sessionId) return;
    const p = m.params;
    if (m.method === 'Runtime.consoleAPICalled' && (p.type === 'error' || p.type === 'assert')) {
      errors.push('console.' + p.type + ': ' + p.args.map((a) => a.value ?? a.description ?? '').join(' '));
    } else if (m.method === 'Runtime.exceptionThrown') {
      const d = p.exceptionDetails;
      errors.push('uncaught exception: ' + ((d.exception && d.exception.description) || d.text));
    } else if (m.method === 'Log.entryAdded' && p.entry.level === 'error') {
      errors.push('log error: ' + p.entry.text + (p.entry.url ? ' (' + p.entry.url + ')' : ''));
    } else if (m.method === 'Page.javascriptDialogOpening') {
      errors.push(`a ${p.type} dialog opened ("${p.message}"): injected script ran`);
      page('Page.handleJavaScriptDialog', { accept: false }).catch(() => {});
    } else if (m.method === 'Network.requestWillBeSent') {
      const url = p.request.url;
      if (!allowUrl(url)) errors.push(networkLabel + url);
    }
  });
}

module.exports = { Cdp, chromiumArgs, watchConsole };
