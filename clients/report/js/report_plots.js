// driftlab report plots: turns each plot spec written by interactive_plot.cc into a dygraphs chart
// (zoom: drag; pan: shift-drag; reset: double-click or the button) with a toolbar: log/linear
// toggles, one checkbox per series, PNG export. Embedded at build time and inlined into every
// report, after dygraphs itself.
//
// Spec fields: labels (x first), data rows [x, y1, ...] (or [x, [lo, y, hi], ...] with bars),
// colors, dashes {series: [on, off]}, widths {series: px}, points_only, xlabel, ylabel, logx, logy,
// equal_axes, step, fill, shades [[x0, x1, color, label]], circles [[cx, cy, r, color, label]],
// vlines [[x, color, label]], segments [[x0, y0, x1, y1, color, label]], markers
// [[x, y, color, label]], info (per data row, the scatter tooltip), name (PNG file name).
(function () {
  'use strict';
  var errors = [];
  window.addEventListener('error', function (e) {
    errors.push(String(e.message));
    document.documentElement.setAttribute('data-errors', errors.join(' | '));
  });

  function number(v) {
    if (v === null || v === undefined || !isFinite(v)) return '-';
    var a = Math.abs(v);
    if (a !== 0 && (a < 1e-3 || a >= 1e6)) return v.toExponential(3);
    return String(+v.toPrecision(5));
  }

  function dash(ctx, d) {
    if (ctx.setLineDash) ctx.setLineDash(d || []);
  }

  // Data -> canvas coordinates on linear or log axes (dygraphs' toDomXCoord maps x linearly even
  // on a log x axis).
  function domX(g, x) {
    if (!g.getOptionForAxis('logscale', 'x')) return g.toDomXCoord(x);
    var r = g.xAxisRange(), a = g.getArea();
    var l0 = Math.log(r[0]), l1 = Math.log(r[1]);
    return a.x + (Math.log(x) - l0) / (l1 - l0) * a.w;
  }

  function dom(g, x, y) {
    return [domX(g, x), g.toDomYCoord(y)];
  }

  // Shaded x intervals, circles, vertical lines, line segments (slope guides) and labelled
  // markers, in data coordinates, under the series.
  function underlay(spec) {
    return function (ctx, area, g) {
      ctx.save();
      ctx.beginPath();
      ctx.rect(area.x, area.y, area.w, area.h);
      ctx.clip();
      (spec.shades || []).forEach(function (s) {
        var a = domX(g, s[0]), b = domX(g, s[1]);
        ctx.fillStyle = s[2];
        ctx.fillRect(a, area.y, Math.max(1, b - a), area.h);
      });
      (spec.vlines || []).forEach(function (v) {
        var x = domX(g, v[0]);
        ctx.strokeStyle = v[1];
        ctx.lineWidth = 2;
        ctx.beginPath();
        ctx.moveTo(x, area.y);
        ctx.lineTo(x, area.y + area.h);
        ctx.stroke();
      });
      (spec.circles || []).forEach(function (c) {
        var p = dom(g, c[0], c[1]);
        var rx = Math.abs(domX(g, c[0] + c[2]) - p[0]);
        var ry = Math.abs(g.toDomYCoord(c[1] + c[2]) - p[1]);
        ctx.strokeStyle = c[3];
        ctx.lineWidth = 2;
        ctx.beginPath();
        ctx.ellipse(p[0], p[1], rx, ry, 0, 0, 2 * Math.PI);
        ctx.stroke();
      });
      (spec.segments || []).forEach(function (s) {
        var a = dom(g, s[0], s[1]), b = dom(g, s[2], s[3]);
        ctx.strokeStyle = s[4];
        ctx.lineWidth = 1;
        dash(ctx, [2, 3]);
        ctx.beginPath();
        ctx.moveTo(a[0], a[1]);
        ctx.lineTo(b[0], b[1]);
        ctx.stroke();
        dash(ctx, []);
        if (s[5]) {
          ctx.fillStyle = s[4];
          ctx.font = '11px sans-serif';
          // At the end of a sloped segment, the start of a level one (guides meet at the right),
          // kept inside the plot area.
          var at = s[1] === s[3] ? a : b;
          var w = ctx.measureText(s[5]).width;
          var x = Math.max(Math.min(at[0] + 3, area.x + area.w - w - 2), area.x + 2);
          var y = Math.max(Math.min(at[1] - 3, area.y + area.h - 3), area.y + 11);
          ctx.fillText(s[5], x, y);
        }
      });
      (spec.markers || []).forEach(function (m) {
        var p = dom(g, m[0], m[1]);
        ctx.fillStyle = m[2];
        ctx.beginPath();
        ctx.arc(p[0], p[1], 4, 0, 2 * Math.PI);
        ctx.fill();
        if (m[3]) {
          ctx.font = 'bold 11px sans-serif';
          var w = ctx.measureText(m[3]).width;
          var left = p[0] + 6 + w > area.x + area.w ? p[0] - 6 - w : p[0] + 6;
          var below = p[1] + 14 < area.y + area.h - 2;
          ctx.fillText(m[3], left, below ? p[1] + 14 : p[1] - 6);
        }
      });
      ctx.restore();
    };
  }

  // A white PNG of the plot (data: URL): the canvases and the axis labels (dygraphs draws those
  // as HTML).
  function pngUrl(div) {
    var box = div.getBoundingClientRect();
    var r = window.devicePixelRatio || 1;
    var canvas = document.createElement('canvas');
    canvas.width = Math.ceil(box.width * r);
    canvas.height = Math.ceil(box.height * r);
    var ctx = canvas.getContext('2d');
    ctx.scale(r, r);
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, box.width, box.height);
    div.querySelectorAll('canvas').forEach(function (c) {
      var b = c.getBoundingClientRect();
      ctx.drawImage(c, b.left - box.left, b.top - box.top, b.width, b.height);
    });
    ctx.fillStyle = '#222';
    ctx.font = '11px sans-serif';
    div.querySelectorAll('.dygraph-axis-label, .dygraph-label').forEach(function (el) {
      var b = el.getBoundingClientRect();
      if (!b.width || !el.textContent) return;
      ctx.save();
      ctx.textBaseline = 'middle';
      ctx.textAlign = 'center';
      ctx.translate(b.left - box.left + b.width / 2, b.top - box.top + b.height / 2);
      if (el.closest('.dygraph-ylabel')) ctx.rotate(-Math.PI / 2);
      ctx.fillText(el.textContent, 0, 0);
      ctx.restore();
    });
    return canvas.toDataURL('image/png');
  }

  // Saves pngUrl(div) as NAME.png (a download).
  function exportPng(div, name) {
    var url = pngUrl(div);
    var a = document.createElement('a');
    a.href = url;
    a.download = (name || 'plot') + '.png';
    document.body.appendChild(a);
    a.click();
    a.remove();
    return url;
  }

  // True when the plot's canvases hold at least one non-transparent pixel.
  function drawn(div) {
    var found = false;
    div.querySelectorAll('canvas').forEach(function (c) {
      if (found || !c.width || !c.height) return;
      var d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      for (var i = 3; i < d.length; i += 4) {
        if (d[i] !== 0) {
          found = true;
          return;
        }
      }
    });
    return found;
  }

  // Scatter plots: the nearest point (within 12 px) under the cursor shows its info text.
  function scatterHover(g, spec, holder, tip) {
    holder.addEventListener('mousemove', function (e) {
      var box = holder.getBoundingClientRect();
      var x = e.clientX - box.left, y = e.clientY - box.top;
      var best = -1, best_d2 = 144;
      for (var i = 0; i < spec.data.length; ++i) {
        var row = spec.data[i];
        for (var s = 1; s < row.length; ++s) {
          if (row[s] === null) continue;
          var p = dom(g, row[0], row[s]);
          var d2 = (p[0] - x) * (p[0] - x) + (p[1] - y) * (p[1] - y);
          if (d2 < best_d2) {
            best_d2 = d2;
            best = i;
          }
        }
      }
      if (best < 0) {
        tip.style.display = 'none';
        return;
      }
      tip.textContent = spec.info[best];
      tip.style.display = 'block';
      tip.style.left = Math.min(x + 12, box.width - 260) + 'px';
      tip.style.top = y + 12 + 'px';
    });
    holder.addEventListener('mouseleave', function () {
      tip.style.display = 'none';
    });
  }

  function checkbox(bar, text, checked, on_change) {
    var label = document.createElement('label');
    var box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = checked;
    box.addEventListener('change', function () {
      on_change(box.checked);
    });
    label.appendChild(box);
    label.appendChild(document.createTextNode(text));
    bar.appendChild(label);
    return box;
  }

  function button(bar, text, on_click) {
    var b = document.createElement('button');
    b.type = 'button';
    b.textContent = text;
    b.addEventListener('click', on_click);
    bar.appendChild(b);
  }

  window.driftlabPlot = function (id, spec) {
    var root = document.getElementById(id);
    var bar = root.querySelector('.dl-toolbar');
    var holder = root.querySelector('.dl-graph');
    var legend = root.querySelector('.dl-legend');
    var series = {};
    spec.labels.slice(1).forEach(function (name, k) {
      series[name] = {
        color: spec.colors[k],
        strokeWidth: spec.points_only ? 0 : (spec.widths && spec.widths[name]) || 1.5,
        strokePattern: spec.dashes && spec.dashes[name] ? spec.dashes[name] : null,
        drawPoints: !!spec.points_only,
        pointSize: spec.points_only ? 2 : 1,
      };
    });
    var options = {
      labels: spec.labels,
      series: series,
      xlabel: spec.xlabel,
      ylabel: spec.ylabel,
      labelsDiv: legend,
      legend: 'always',
      labelsSeparateLines: false,
      customBars: !!spec.bars,
      fillAlpha: 0.3,
      stepPlot: !!spec.step,
      fillGraph: !!spec.fill,
      connectSeparatedPoints: !spec.points_only,
      logscale: !!spec.logy,
      axes: {
        x: {logscale: !!spec.logx, valueFormatter: number, axisLabelFormatter: number,
            axisLabelWidth: 60},
        y: {valueFormatter: number, axisLabelFormatter: number, axisLabelWidth: 62},
      },
      yLabelWidth: 18,
      highlightCircleSize: 3,
      underlayCallback: underlay(spec),
      animatedZooms: false,
    };
    if (spec.xrange) options.dateWindow = spec.xrange;
    if (spec.yrange) options.valueRange = spec.yrange;
    var g = new Dygraph(holder, spec.data, options);
    if (spec.equal_axes) {
      // Same metres per pixel on both axes: widen the shorter axis's range about its centre.
      var area = g.getArea(), xr = g.xAxisRange(), yr = g.yAxisRange();
      var per_px = Math.max((xr[1] - xr[0]) / area.w, (yr[1] - yr[0]) / area.h);
      var xc = (xr[0] + xr[1]) / 2, yc = (yr[0] + yr[1]) / 2;
      g.updateOptions({
        dateWindow: [xc - per_px * area.w / 2, xc + per_px * area.w / 2],
        valueRange: [yc - per_px * area.h / 2, yc + per_px * area.h / 2],
      });
    }
    if (spec.info) {
      var tip = document.createElement('div');
      tip.className = 'dl-tip';
      holder.appendChild(tip);
      scatterHover(g, spec, holder, tip);
    }
    checkbox(bar, 'log x', !!spec.logx, function (on) {
      g.updateOptions({axes: {x: {logscale: on}}});
    });
    checkbox(bar, 'log y', !!spec.logy, function (on) {
      g.updateOptions({logscale: on});
    });
    if (spec.labels.length > 2) {
      spec.labels.slice(1).forEach(function (name, k) {
        var box = checkbox(bar, name, true, function (on) {
          g.setVisibility(k, on);
        });
        box.parentNode.style.color = spec.colors[k];
      });
    }
    button(bar, 'reset zoom', function () {
      g.resetZoom();
    });
    button(bar, 'PNG', function () {
      exportPng(holder, spec.name);
    });
    root.setAttribute('data-drawn', drawn(holder) ? 'yes' : 'no');
    root.driftlabGraph = g;
    root.driftlabPngUrl = function () {
      return pngUrl(holder);
    };
  };
})();
