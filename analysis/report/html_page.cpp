#include "analysis/report/html_page.h"

namespace lucent::analysis {

std::string images_drawn_script() {
    return "<script>window.addEventListener('load',function(){var im=document.images,n=0;"
           "for(var i=0;i<im.length;++i)if(im[i].complete&&im[i].naturalWidth>0)++n;"
           "document.documentElement.setAttribute('data-images-drawn',n+'/"
           "'+im.length);});"
           "</script>\n";
}

}  // namespace lucent::analysis
