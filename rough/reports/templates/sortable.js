// Click a header of a table of class "sortable" to sort its rows by that column:
// numerically by the cells' data-value when every filled one is a number, else by text;
// a second click reverses. Empty cells (undefined values) stay at the end.
(function () {
  function key(cell) {
    return cell.hasAttribute("data-value") ? cell.getAttribute("data-value") : cell.textContent.trim();
  }
  function sort(table, column, header) {
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var filled = rows.filter(function (row) { return key(row.cells[column]) !== ""; });
    var empty = rows.filter(function (row) { return key(row.cells[column]) === ""; });
    var numeric = filled.every(function (row) { return !isNaN(parseFloat(key(row.cells[column]))); });
    var descending = header.classList.contains("sorted-ascending");
    filled.sort(function (a, b) {
      var x = key(a.cells[column]), y = key(b.cells[column]);
      var order = numeric ? parseFloat(x) - parseFloat(y) : x.localeCompare(y);
      return descending ? -order : order;
    });
    Array.prototype.forEach.call(header.parentNode.cells, function (th) {
      th.classList.remove("sorted-ascending", "sorted-descending");
    });
    header.classList.add(descending ? "sorted-descending" : "sorted-ascending");
    filled.concat(empty).forEach(function (row) { body.appendChild(row); });
  }
  Array.prototype.forEach.call(document.querySelectorAll("table.sortable"), function (table) {
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (header, column) {
      header.addEventListener("click", function () { sort(table, column, header); });
    });
  });
})();
