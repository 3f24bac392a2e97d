// driftlab web pages: refreshes the parts of a page that change while jobs run. Each element with
// data-poll="URL" is replaced by the HTML fragment the server renders at URL (the same renderer
// as the page itself), every second while a job in it is queued or running (data-active="1" or a
// data-state that is not final), else every five seconds. A job page reloads once its job
// reaches a final state, to show the result. Without JavaScript the pages work as they are
// (reload to refresh). Served from the server (CSP script-src 'self'); no external resource.
'use strict';
(function () {
  var FINAL = {SUCCEEDED: true, FAILED: true, CANCELLED: true};

  function active(el) {
    if (el.hasAttribute('data-state')) return !FINAL[el.getAttribute('data-state')];
    return el.getAttribute('data-active') === '1';
  }

  function poll(el) {
    var url = el.getAttribute('data-poll');
    var updates = 0;
    function schedule() {
      window.setTimeout(tick, active(el) ? 1000 : 5000);
    }
    function tick() {
      fetch(url, {credentials: 'same-origin', cache: 'no-store'})
        .then(function (response) {
          if (response.status === 401) {
            window.location.assign('/signin');
            return null;
          }
          if (!response.ok) return null;
          var state = response.headers.get('X-Driftlab-State');
          var busy = response.headers.get('X-Driftlab-Active');
          return response.text().then(function (html) {
            if (state !== null) {
              var before = el.getAttribute('data-state');
              el.setAttribute('data-state', state);
              if (FINAL[state] && !FINAL[before]) {
                window.location.reload();
                return;
              }
            }
            if (busy !== null) el.setAttribute('data-active', busy);
            el.innerHTML = html;
            el.setAttribute('data-updates', String(++updates));
          });
        })
        .catch(function () {})
        .then(schedule);
    }
    schedule();
  }

  function init() {
    document.querySelectorAll('[data-poll]').forEach(poll);
    // The state checkboxes of the job filter apply at once.
    document.querySelectorAll('form.filters input[type=checkbox]').forEach(function (box) {
      box.addEventListener('change', function () { box.form.submit(); });
    });
  }

  if (document.readyState === 'loading') {
    document.addEventListener('DOMContentLoaded', init);
  } else {
    init();
  }
})();
