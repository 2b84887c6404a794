
function gilabImageError(img) {
  img.classList.add("broken");
  console.error("gilab report: cannot load image " + img.getAttribute("src"));
}
