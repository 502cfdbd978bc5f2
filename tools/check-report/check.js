// Loaded by a <script> that check-report.sh injects at the start of <head>
// of a copy of the report, which it then loads in headless Chromium with
// --dump-dom, reading the verdict this script leaves in a hidden <pre> (id
// cdpr-report-check): one "FAIL <what>" line per problem, "info" lines for
// the record. It runs before any script of the report so that it sees every
// error, and checks once the page and everything in it loaded.
(function () {
  'use strict';
  var problems = [];
  var fail = function (text) { problems.push('FAIL ' + text); };

  // Script errors, resources that failed to load (capture phase: load errors
  // do not bubble), console.error and rejected promises nobody handled.
  window.addEventListener('error', function (event) {
    var target = event.target;
    if (target && target !== window && target.nodeType === 1) {
      fail('resource did not load: <' + target.tagName.toLowerCase() + '> ' +
           (target.src || target.href || target.data || ''));
    } else {
      fail('script error: ' + event.message + ' (' + event.filename + ':' + event.lineno + ')');
    }
  }, true);
  window.addEventListener('unhandledrejection', function (event) {
    fail('unhandled promise rejection: ' + event.reason);
  });
  var consoleError = console.error;
  console.error = function () {
    fail('console error: ' + Array.prototype.join.call(arguments, ' '));
    return consoleError.apply(console, arguments);
  };
  document.addEventListener('securitypolicyviolation', function (event) {
    fail('content security policy blocked ' + event.blockedURI);
  });

  // "svg#2 'title'", "pre.summary 'first words'": enough to find it in the report.
  function describe(element) {
    var name = element.tagName.toLowerCase();
    if (element.id) name += '#' + element.id;
    var classes = element.getAttribute('class');
    if (classes && classes.trim()) name += '.' + classes.trim().split(/\s+/).join('.');
    var text = (element.textContent || '').replace(/\s+/g, ' ').trim();
    if (text.length > 60) text = text.slice(0, 57) + '...';
    return text ? name + ' "' + text + '"' : name;
  }

  function inside(element, ancestors) {
    for (var node = element.parentElement; node; node = node.parentElement) {
      if (ancestors.indexOf(node) >= 0) return true;
    }
    return false;
  }

  function round(value) { return Math.round(value); }

  // Whatever a reader can unfold must fit too: every <details> is opened
  // before measuring (the screenshots are taken of the page as it opens).
  function openDetails() {
    var all = document.querySelectorAll('details');
    for (var i = 0; i < all.length; ++i) all[i].open = true;
  }

  // Anything that reaches past the viewport's right (or left) edge, either
  // its own box or its content (a <pre> whose lines run on, a table behind
  // a horizontal scroll bar). Only the outermost culprits are named.
  function checkWidth(width) {
    var page = document.documentElement.scrollWidth;
    if (page > width + 1) {
      fail('the page scrolls sideways: content ' + page + ' px wide in a ' + width + ' px viewport');
    }
    var culprits = [];
    var all = document.body ? document.body.getElementsByTagName('*') : [];
    for (var i = 0; i < all.length; ++i) {
      var element = all[i];
      if (element.closest('svg') && element.tagName.toLowerCase() !== 'svg') continue;
      if (element.tagName.toLowerCase() === 'svg' && element.parentElement.closest('svg')) continue;
      var box = element.getBoundingClientRect();
      if (box.width === 0 && box.height === 0) continue;
      var right = Math.max(box.right, box.left + element.scrollWidth);
      if (right <= width + 0.5 && box.left >= -0.5) continue;
      if (inside(element, culprits)) continue;
      culprits.push(element);
      fail('wider than the viewport: ' + describe(element) + ' spans ' + round(box.left) + '..' +
           round(right) + ' px, viewport ' + width + ' px');
    }
  }

  // Plots are the <svg> elements not inside another one, unless marked
  // decorative (role="presentation"/"none" or aria-hidden="true"). Their data
  // marks are the shapes in elements of class "data" when the plot has any,
  // otherwise every circle, ellipse, path, polygon and polyline (axes,
  // frames and grid are lines and rects). A plot needs one visible mark
  // (non-empty, inside the plot); no label may be cut off by the plot's edge.
  function checkPlots() {
    var plots = [];
    var svgs = document.getElementsByTagName('svg');
    for (var i = 0; i < svgs.length; ++i) {
      var svg = svgs[i];
      if (svg.parentElement && svg.parentElement.closest('svg')) continue;
      var role = svg.getAttribute('role');
      if (role === 'presentation' || role === 'none' || svg.getAttribute('aria-hidden') === 'true') continue;
      plots.push(svg);
    }
    var totalMarks = 0, untagged = 0;
    plots.forEach(function (svg, index) {
      var frame = svg.getBoundingClientRect();
      var title = svg.querySelector('title, text');
      var name = 'plot ' + (index + 1) + (title ? ' "' + title.textContent.trim() + '"' : '');
      if (frame.width === 0 || frame.height === 0) {
        fail('plot not shown: ' + name + ' has no size');
        return;
      }
      var tagged = svg.querySelector('.data') !== null;
      if (!tagged) ++untagged;
      var shapes = svg.querySelectorAll(tagged ? '.data, .data *' : 'circle, ellipse, path, polygon, polyline');
      var marks = 0;
      for (var j = 0; j < shapes.length; ++j) {
        var box = shapes[j].getBoundingClientRect();
        if (box.width === 0 && box.height === 0) continue;
        if (box.right < frame.left || box.left > frame.right || box.bottom < frame.top || box.top > frame.bottom) continue;
        if (/^(circle|ellipse|line|path|polygon|polyline|rect|use|image)$/.test(shapes[j].tagName.toLowerCase())) ++marks;
      }
      totalMarks += marks;
      if (marks === 0) fail('empty plot: ' + name + ' has no data marks');
      var texts = svg.querySelectorAll('text');
      for (var k = 0; k < texts.length; ++k) {
        var label = texts[k].getBoundingClientRect();
        if (label.width === 0) continue;
        if (label.left < frame.left - 0.5 || label.right > frame.right + 0.5 ||
            label.top < frame.top - 0.5 || label.bottom > frame.bottom + 0.5) {
          fail('label cut off by the plot edge: "' + texts[k].textContent.trim() + '" in ' + name);
        }
      }
    });
    return { plots: plots.length, marks: totalMarks, untagged: untagged };
  }

  // Self-contained: nothing loaded but the page itself, data: URLs and
  // this script.
  function checkResources() {
    var entries = performance.getEntriesByType('resource');
    for (var i = 0; i < entries.length; ++i) {
      if (/^(data|blob|about):/.test(entries[i].name) || /\/cdpr-report-check\.js$/.test(entries[i].name)) continue;
      fail('loads ' + entries[i].name + ' (not self-contained)');
    }
  }

  function check() {
    openDetails();
    var width = document.documentElement.clientWidth;
    checkWidth(width);
    var found = checkPlots();
    checkResources();
    var verdict = document.createElement('pre');
    verdict.id = 'cdpr-report-check';
    verdict.hidden = true;
    var lines = ['info viewport ' + width + ' px', 'info plots ' + found.plots + ', data marks ' + found.marks];
    if (found.untagged > 0) {
      lines.push('info ' + found.untagged + ' plots mark no element of class "data": every circle, ellipse, path, ' +
                 'polygon and polyline counted as data (legend swatches too)');
    }
    verdict.textContent = lines.concat(problems).join('\n');
    (document.body || document.documentElement).appendChild(verdict);
  }

  // After the load event's own handlers (a report may draw then).
  window.addEventListener('load', function () { setTimeout(check, 0); });
})();
