"""The effects catalogue of the model lab: checkboxes by category, and a pane explaining each effect.

Effects of one category are alternatives (analysis.model.composed allows one per
category): checking a second one swaps it for the first, like radio buttons
that may also all be off. Effects of the user's own (analysis.effects.registry:
the user folder, packages) have a branch of their own, "User effects", with the
"New effect…" button that writes one.
"""
from __future__ import annotations

import html

from PySide6.QtCore import QEvent, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (QAbstractItemView, QHBoxLayout, QHeaderView, QLabel, QPushButton, QSizePolicy,
                               QSplitter, QTextBrowser, QTreeWidget, QTreeWidgetItem, QVBoxLayout, QWidget)

from analysis.effects import Effect, categories, registry
from app.widgets import style
from app.widgets.column_widths import fit_to_contents, sized_when_filled

EFFECT_ROLE = Qt.UserRole
CATEGORY_TITLES = {       # the ids are for code; these are for the reader
    "inductance": "Voice-coil inductance",
    "creep": "Suspension creep",
    "electrical-channel": "Current channel",
    "displacement-sensor": "Displacement sensor",
    "breakup": "Cone break-up",
    "cone-spot": "Cone mode at the laser spot",
    "force-factor": "Force factor",
    "air-load": "Air load",
    "damping": "Mechanical damping",
    "enclosure": "Enclosure (box)",
}
NO_DISPLACEMENT = "needs the displacement channel, which this recording does not have"
USER_BRANCH = "User effects"
HINT = ("Check an effect to add it to the model and refit; uncheck it to remove it. One effect per category: "
        "checking another swaps it. Point at an effect to read what it is.")


def category_title(category: str) -> str:
    return CATEGORY_TITLES.get(category, category.replace("-", " ").capitalize())


def effect_html(effect: Effect, available: bool = True) -> str:
    """The catalogue entry of an effect, for the detail pane."""
    e = html.escape
    rows = "".join(
        f"<tr><td><b>{e(p.name)}</b></td><td>{e(p.display_unit)}</td><td>{e(p.description)}"
        + (f"; typically {e(p.typical_text())} (a fit outside is flagged)" if p.typical else "") + "</td></tr>"
        for p in effect.params)
    own = registry.is_user_effect(effect)
    category = "a category of its own" if own and effect.category == effect.id else category_title(effect.category)
    parts = [
        f"<h3 style='margin-bottom:2px'>{e(effect.title)}</h3>",
        f"<p style='margin-top:0'><code>{e(effect.id)}</code> · {e(category)} · "
        f"acts on the {e(effect.site.value)}</p>",
    ]
    if not available:
        parts.append(f"<p style='color:{style.MISSING_TEXT}'><i>Not available: {e(NO_DISPLACEMENT)}.</i></p>")
    formula = getattr(effect, "formula", None)
    if formula is not None:
        parts.append(f"<p><b>Your own effect.</b> <code>{e(formula.text)}</code>: {e(effect.acts_as)}. "
                     f"From {e(registry.source_of(effect))}.</p>")
    elif registry.source_of(effect):
        parts.append(f"<p><b>From a package:</b> {e(registry.source_of(effect))}.</p>")
    parts += [
        f"<p><b>Physics.</b> {e(effect.physics)}</p>",
        f"<p><b>The residual it cures.</b> {e(effect.signature)}</p>",
        f"<p><b>Typical values.</b> {e(effect.typical)}</p>",
        f"<p><b>Parameters</b></p><table cellspacing='0' cellpadding='2'>{rows}</table>",
        f"<p><b>Reference.</b> {e(effect.reference)}</p>",
    ]
    if effect.notes and formula is None:        # an own effect's notes repeat its formula and file, said above
        parts.append(f"<p><b>Notes.</b> {e(effect.notes)}</p>")
    return "".join(parts)


class EffectCatalogue(QWidget):
    # The user changed the checked effects: their ids, in catalogue order.
    selection_changed = Signal(tuple)
    new_effect_requested = Signal()     # "New effect…" was clicked

    def __init__(self, parent=None):
        super().__init__(parent)
        self._items: dict[str, QTreeWidgetItem] = {}
        self._by_category: dict[str, list[str]] = {}
        self._available: dict[str, bool] = {}
        self._displacement = True          # whether the recording has Hx (effects that need it are greyed)
        self._updating = False

        self.tree = QTreeWidget()
        self.tree.setHeaderHidden(True)
        # The id with its checkbox, then the title: the titles are long and QTreeView cannot wrap
        # text in an indented column, so the title is the part that gets elided (the pane has it whole).
        self.tree.setColumnCount(2)
        self.tree.setSelectionMode(QAbstractItemView.SingleSelection)
        self.tree.setMouseTracking(True)           # itemEntered: explain the effect under the pointer
        sized_when_filled(self.tree, (0,))      # the ids measured when the list changes, not at each show
        # Categories are headings, always open: no expand arrows, and little indentation, so the
        # narrow column keeps its room for the titles.
        self.tree.setRootIsDecorated(False)
        self.tree.setItemsExpandable(False)
        self.tree.setIndentation(10)
        # The title takes the room the ids leave, down to a few letters, cut with "…" (its tooltip and the pane
        # below have it whole): stretched as the last section it kept a width of 100 px, wider than the room on
        # a 1280 px screen, and hid its end behind a horizontal scroll bar.
        self.tree.header().setStretchLastSection(False)
        self.tree.header().setSectionResizeMode(1, QHeaderView.Stretch)
        self.tree.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        self.tree.setTextElideMode(Qt.ElideRight)
        self.tree.viewport().installEventFilter(self)
        self._bold = QFont()
        self._bold.setBold(True)
        for category, effects in categories().items():
            head = self._heading(category_title(category), f"{category_title(category)}: at most one of these in a model")
            for effect in effects:
                self._add_item(head, effect)
        self.user_head = self._heading(USER_BRANCH, "Effects of your own: files in the user folder, --effects-file, "
                                                    "packages; New effect… writes one")
        self._problems: list[str] = []
        self.refresh_user_effects()
        self.tree.expandAll()
        fit_to_contents(self.tree, (0,))
        self.tree.itemChanged.connect(self.on_item_changed)
        self.tree.itemEntered.connect(self.on_item_entered)
        self.tree.currentItemChanged.connect(self.on_current_changed)

        self.detail = QTextBrowser()
        self.detail.setOpenExternalLinks(False)
        self._detail_html = f"<p>{html.escape(HINT)}</p>"        # what the detail pane shows
        self.detail.setHtml(self._detail_html)

        title = QLabel("<b>Effects</b> (one per category)")
        self.new_effect_button = QPushButton("New effect…")
        self.new_effect_button.setToolTip("Write an effect of your own: its formula, site and parameters, checked as "
                                          "you type, previewed on this recording; saved to the user folder")
        self.new_effect_button.clicked.connect(self.new_effect_requested)
        # The title gives way before the button: the lab's left pane must not widen the window's minimum.
        title.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Preferred)
        header = QHBoxLayout()
        header.addWidget(title, 1)
        header.addWidget(self.new_effect_button)
        splitter = QSplitter(Qt.Vertical)
        splitter.addWidget(self.tree)
        splitter.addWidget(self.detail)
        splitter.setSizes([320, 420])     # the list needs ~300 px; the rest goes to the explanation
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(header)
        layout.addWidget(splitter, 1)

    # -- building ----------------------------------------------------------
    def _heading(self, text: str, tooltip: str) -> QTreeWidgetItem:
        head = QTreeWidgetItem([text])
        head.setFont(0, self._bold)
        head.setFlags(Qt.ItemIsEnabled)
        head.setToolTip(0, tooltip)
        self.tree.addTopLevelItem(head)
        head.setFirstColumnSpanned(True)
        return head

    def _add_item(self, head: QTreeWidgetItem, effect: Effect) -> None:
        item = QTreeWidgetItem([effect.id, effect.title])
        item.setData(0, EFFECT_ROLE, effect)
        item.setFlags(Qt.ItemIsEnabled | Qt.ItemIsSelectable | Qt.ItemIsUserCheckable)
        item.setCheckState(0, Qt.Unchecked)
        self._set_tooltip(item, f"{effect.title}. Cures: {effect.signature}")
        head.addChild(item)
        self._items[effect.id] = item
        self._by_category.setdefault(effect.category, []).append(effect.id)
        self._available[effect.id] = True

    def set_problems(self, problems: list[str]) -> None:
        """Effect files of the user folder that could not be read (one line each): said in the branch."""
        self._problems = list(problems)
        self.refresh_user_effects()

    def refresh_user_effects(self) -> None:
        """Rebuild the "User effects" branch from the registry (after a new effect was saved)."""
        checked = set(self.checked())
        self._updating = True
        try:
            for i in reversed(range(self.user_head.childCount())):
                effect = self.user_head.child(i).data(0, EFFECT_ROLE)
                self.user_head.removeChild(self.user_head.child(i))
                if effect is not None:
                    self._items.pop(effect.id, None)
                    self._available.pop(effect.id, None)
                    self._by_category[effect.category].remove(effect.id)
            for effect in registry.user_effects():
                self._add_item(self.user_head, effect)
                self._items[effect.id].setCheckState(0, Qt.Checked if effect.id in checked else Qt.Unchecked)
            if not registry.user_effects():
                note = QTreeWidgetItem(["none yet", "New effect… writes one to the user folder"])
                note.setFlags(Qt.ItemIsEnabled)
                note.setForeground(0, QBrush(QColor(style.MISSING_TEXT)))
                note.setForeground(1, QBrush(QColor(style.MISSING_TEXT)))
                self._set_tooltip(note, f"The user folder: {registry.user_folder()}")
                self.user_head.addChild(note)
            if self._problems:
                bad = QTreeWidgetItem([f"{len(self._problems)} file(s) not read", self._problems[0]])
                bad.setFlags(Qt.ItemIsEnabled)
                for column in (0, 1):
                    bad.setForeground(column, QBrush(QColor(style.MISSING_TEXT)))
                self._set_tooltip(bad, "\n".join(self._problems))
                self.user_head.addChild(bad)
            self.user_head.setExpanded(True)
        finally:
            self._updating = False
        self.set_displacement_available(self._displacement)
        fit_to_contents(self.tree, (0,))

    # -- state -------------------------------------------------------------
    def checked(self) -> tuple[str, ...]:
        return tuple(i for i, item in self._items.items() if item.checkState(0) == Qt.Checked)

    def item(self, effect_id: str) -> QTreeWidgetItem:
        return self._items[effect_id]

    def set_checked(self, effect_ids) -> None:
        """Show a model's effects; emits nothing (the model is already fitted)."""
        wanted = set(effect_ids)
        self._updating = True
        try:
            for effect_id, item in self._items.items():
                item.setCheckState(0, Qt.Checked if effect_id in wanted else Qt.Unchecked)
        finally:
            self._updating = False

    def set_displacement_available(self, available: bool) -> None:
        """Without Hx, effects on the displacement channel (or needing Bl) cannot act: shown, but not checkable."""
        self._displacement = available
        self._updating = True
        try:
            for effect_id, item in self._items.items():
                effect: Effect = item.data(0, EFFECT_ROLE)
                ok = available or not effect.needs_displacement
                self._available[effect_id] = ok
                flags = Qt.ItemIsEnabled | Qt.ItemIsSelectable | (Qt.ItemIsUserCheckable if ok else Qt.NoItemFlags)
                item.setFlags(flags)
                for column in (0, 1):
                    item.setForeground(column, QBrush() if ok else QBrush(QColor(style.MISSING_TEXT)))
                self._set_tooltip(item, f"{effect.title}. Cures: {effect.signature}" if ok
                                  else f"{effect.title}: {NO_DISPLACEMENT}")
        finally:
            self._updating = False

    @staticmethod
    def _set_tooltip(item: QTreeWidgetItem, text: str) -> None:
        for column in (0, 1):
            item.setToolTip(column, text)

    def show_effect(self, effect_id: str) -> None:
        item = self._items[effect_id]
        text = effect_html(item.data(0, EFFECT_ROLE), self._available[effect_id])
        if text != self._detail_html:       # the entry shown already: laid out again for nothing (1.5-2.7 ms)
            self._detail_html = text
            self.detail.setHtml(text)

    # -- slots -------------------------------------------------------------
    def on_item_changed(self, item: QTreeWidgetItem, _column: int) -> None:
        effect: Effect | None = item.data(0, EFFECT_ROLE)
        if self._updating or effect is None:
            return
        if item.checkState(0) == Qt.Checked:
            self._updating = True
            try:
                for other in self._by_category[effect.category]:
                    if other != effect.id:
                        self._items[other].setCheckState(0, Qt.Unchecked)
            finally:
                self._updating = False
        self.show_effect(effect.id)
        self.selection_changed.emit(self.checked())

    def on_item_entered(self, item: QTreeWidgetItem, _column: int) -> None:
        effect: Effect | None = item.data(0, EFFECT_ROLE)
        if effect is not None:
            self.show_effect(effect.id)

    def on_current_changed(self, current: QTreeWidgetItem | None, _previous) -> None:
        effect: Effect | None = current.data(0, EFFECT_ROLE) if current is not None else None
        if effect is not None:
            self.show_effect(effect.id)

    def eventFilter(self, watched, event) -> bool:
        # Leaving the list: back to the selected effect, so hovering never loses what was being read.
        if event.type() == QEvent.Leave:
            current = self.tree.currentItem()
            effect = current.data(0, EFFECT_ROLE) if current is not None else None
            if effect is not None:
                self.show_effect(effect.id)
        return super().eventFilter(watched, event)
